// Forward sensitivities (docs/sensitivities.md): the IDAS sensitivities of a run against
// closed forms (a spring-mass-damper, the rigid slider crank's kinematics) and against
// central differences of whole runs (a pendulum, the slider crank's reactions), the
// consistent initial sensitivities against the differentiated constraints, and bad input
// through the command line (exit 2 with the parameter named).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "sensitivity_test_support.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "sensitivity/sensitivity_run.hpp"
#include "results/results_writer.hpp"
#include "scene/scene_path.hpp"
#include "results/sensitivity_results.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

// ----- (a) a linear spring-mass-damper: closed form -----------------------------------


/// u(t) of the underdamped oscillator from u0 at rest: u0 e^{-zeta wn t} (cos wd t +
/// zeta wn / wd sin wd t) (e.g. Meirovitch, Elements of Vibration Analysis, eq. 2.27),
/// in complex arithmetic for the complex-step derivative.
std::complex<double> oscillator(double t, std::complex<double> k, std::complex<double> c, std::complex<double> m) {
  const double u0 = 0.1;
  const std::complex<double> wn = std::sqrt(k / m), zeta = c / (2.0 * std::sqrt(k * m));
  const std::complex<double> wd = wn * std::sqrt(1.0 - zeta * zeta);
  return u0 * std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
}

TEST(Sensitivities, SpringMassDamperMatchesClosedFormDerivatives) {
  const SensitivityRun run =
      runWithSensitivities(springMassDamper(), {"forces[0].stiffness", "forces[0].damping", "bodies[0].mass"});
  ASSERT_TRUE(run.summary.ok) << run.summary.message;
  // complex-step derivative of the closed form: exact to round-off (Squire & Trapp 1998)
  const double k = 50.0, c = 0.8, m = 2.0, e = 1e-30;
  const std::complex<double> I(0.0, 1.0);
  // The sensitivities are integrated with the state's tolerances scaled by the parameter
  // (rtol 1e-10): their global error stays below 1e-7 of the largest derivative over 3 s
  // (about 14 periods of error growth); dF/dp is exact here (F is linear in k, c and in m
  // through M v'), up to the round-off eps |F| / h ~ 1e-11 of the central difference.
  const double kRelativeTolerance = 1e-7;
  double largest[3] = {0, 0, 0}, worst[3] = {0, 0, 0};
  for (std::size_t r = 0; r < run.rows.size(); ++r) {
    const double t = run.rows[r][0];
    const double exact[3] = {std::imag(oscillator(t, k + I * e, c, m)) / e, std::imag(oscillator(t, k, c + I * e, m)) / e,
                             std::imag(oscillator(t, k, c, m + I * e)) / e};
    EXPECT_NEAR(run.value(r, "mass.x") - 1.0, std::real(oscillator(t, k, c, m)), 1e-8) << "t = " << t;
    for (std::size_t i = 0; i < 3; ++i) {
      largest[i] = std::max(largest[i], std::fabs(exact[i]));
      worst[i] = std::max(worst[i], std::fabs(run.d(r, "mass.x", i) - exact[i]));
    }
  }
  for (std::size_t i = 0; i < 3; ++i) {
    std::printf("spring-mass-damper dx/dp%zu: worst %.3g of the largest %.3g\n", i, worst[i] / largest[i], largest[i]);
    EXPECT_GT(largest[i], 0.0);
    EXPECT_LT(worst[i], kRelativeTolerance * largest[i]) << "parameter " << i << ": largest " << largest[i];
  }
  // the velocity column's derivative too: d(x_dot)/dk = d/dt (dx/dk), checked at the end
  // against the complex-step derivative of u' (difference of u over +-1e-6 s: error 1e-12 u''')
  const double t = run.rows.back()[0], dt = 1e-6;
  const double dvdk =
      (std::imag(oscillator(t + dt, k + I * e, c, m)) - std::imag(oscillator(t - dt, k + I * e, c, m))) / (e * 2 * dt);
  EXPECT_NEAR(run.d(run.rows.size() - 1, "mass.x_dot", 0), dvdk, 1e-6 * largest[0] * std::sqrt(k / m));
}

// ----- (b) a rigid pendulum: central differences of whole runs --------------------------


TEST(Sensitivities, PendulumAngleByLengthMatchesWholeRuns) {
  const json scene = pendulum();
  const SensitivityRun run = runWithSensitivities(scene, {"joints[0].points[1][1]"});
  ASSERT_TRUE(run.summary.ok) << run.summary.message;
  // Whole runs at L (1 +- 1e-4) with rtol 1e-11. The central difference's truncation error
  // grows as dL^2 (the phase error of theta(t) ~ t sqrt(g / L) accumulates): measured
  // 2.7e-4, 2.7e-6 at relative steps 1e-2, 1e-3, so ~3e-8 at 1e-4; the runs' global errors
  // (~1e-10 rad) over 2 dL = 1.6e-4 m add up to ~6e-7 rad/m. 1e-6 of the largest
  // derivative (0.9 rad/m) holds both; the sensitivity itself is integrated at the run's rtol.
  const double kRelativeTolerance = 1e-6;
  const auto [worst, largest] = againstWholeRuns(scene, run, 0, "joints[0].points[1][1]", "bob.theta", 1e-4);
  std::printf("pendulum dtheta/dL: worst %.3g of the largest %.3g\n", worst / largest, largest);
  EXPECT_GT(largest, 0.1);  // the period changes with L: theta(t) depends on it
  EXPECT_LT(worst, kRelativeTolerance * largest) << "largest " << largest;
}

// ----- (c) the rigid slider crank --------------------------------------------------------

json sliderCrank() {
  json j = json::parse(readFile(kExample));
  j["solver"]["rtol"] = 1e-11;
  j["solver"]["atol"] = 1e-13;
  j["solver"]["t_end"] = 3.0;
  return j;
}

TEST(Sensitivities, SliderCrankPositionByRodLengthMatchesClosedForm) {
  // the slider at x = l1 cos(theta) + sqrt(l2^2 - l1^2 sin^2 theta): dx/dl2 = l2 / sqrt(l2^2 - l1^2 sin^2 theta)
  const SensitivityRun run = runWithSensitivities(sliderCrank(), {"joints[2].points[0][0]"});
  ASSERT_TRUE(run.summary.ok) << run.summary.message;
  // The driven crank's angle is exact; the slider follows the constraints to the Newton
  // tolerance of the corrector (~1e-12 m), so the sensitivity meets the closed form to the
  // integration tolerance: 1e-8 of dx/dl2 ~ 1 (the initial difference quotient adds 1e-10).
  const double kTolerance = 1e-8;
  double worst = 0.0;
  for (std::size_t r = 0; r < run.rows.size(); ++r) {
    const double th = run.value(r, "crank.theta"), l1 = 1.0, l2 = 2.0;
    const double exact = l2 / std::sqrt(l2 * l2 - l1 * l1 * std::sin(th) * std::sin(th));
    EXPECT_NEAR(run.d(r, "slider.x", 0), exact, kTolerance) << "t = " << run.rows[r][0];
    worst = std::max(worst, std::fabs(run.d(r, "slider.x", 0) - exact));
  }
  std::printf("slider crank dx/dl2 against the closed form: worst %.3g\n", worst);
}

TEST(Sensitivities, SliderCrankReactionsMatchWholeRuns) {
  const json scene = sliderCrank();
  const SensitivityRun run = runWithSensitivities(scene, {"bodies[2].mass", "joints[2].points[0][0]"});
  ASSERT_TRUE(run.summary.ok) << run.summary.message;
  // The motor's effort and the slider's acceleration are algebraic in the state; whole runs
  // at p (1 +- 1e-4): truncation (1e-4)^2 / 6 ~ 2e-9 relative, run noise ~1e-10 / 2e-4 ~ 5e-7
  // of the state's scale; 1e-5 of the largest derivative holds both.
  const double kRelativeTolerance = 1e-5;
  // (the slider's acceleration is kinematic: independent of its mass, so only with l2)
  struct Case {
    std::size_t parameter;
    std::string path, column;
  };
  for (const Case& c : {Case{0, "bodies[2].mass", "motor.effort"}, Case{0, "bodies[2].mass", "O3.fx"},
                        Case{1, "joints[2].points[0][0]", "motor.effort"}, Case{1, "joints[2].points[0][0]", "O3.fx"},
                        Case{1, "joints[2].points[0][0]", "slider.x_ddot"}}) {
    const std::size_t i = c.parameter;
    const std::string& path = c.path;
    {
      const std::string& column = c.column;
      const auto [worst, largest] = againstWholeRuns(scene, run, i, path, column, 1e-4);
      std::printf("slider crank d%s/d%s: worst %.3g of the largest %.3g\n", column.c_str(), path.c_str(),
                  worst / largest, largest);
      EXPECT_GT(largest, 1e-3) << column << " / " << path;
      EXPECT_LT(worst, kRelativeTolerance * largest) << column << " / " << path << ": largest " << largest;
    }
  }
}

// ----- (d) consistent initial sensitivities ----------------------------------------------

TEST(Sensitivities, InitialSensitivitiesSatisfyTheDifferentiatedConstraints) {
  const json scene = sliderCrank();
  const std::string text = scene.dump();
  const Scene base = parseSceneText(text);
  const SensitivityScenes sc = buildSensitivityScenes(text, "<scene>", base, {"joints[2].points[0][0]"});
  const System& sys = base.system;
  const double t0 = base.solver.tStart;
  const ConsistentState init = computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  const PerturbedDaes perturbed = perturbedDaes(dae, sc.parameters);
  const ResidualDifferences::Stencil& stencil = perturbed.stencils[0];
  const double h = sc.parameters[0].step;
  const InitialSensitivities s = initialSensitivities(dae, perturbed.stencils, init, t0);
  const DaeLayout& L = dae.layout();
  const VecX sq = s.s0.col(0).segment(L.q, L.nq), sv = s.s0.col(0).segment(L.v, L.nv);
  EXPECT_NEAR(sq[7 - 1], 1.0, 1e-9);  // slider.x moves with the rod's length at theta = 0
  // d/dp g(q(p), p) = G s_q + g_p and d/dp (G v + g_t) = 0, as the five-point difference of
  // the constraints of the perturbed systems along s: exact to O(h^4) ~ 1e-12 (h = 1e-3),
  // its round-off 0.95 eps |g| / h ~ 1e-13 and the Newton tolerance of the projection over
  // h (1e-15 / 1e-3); 1e-10 holds them all.
  const double kTolerance = 1e-10;
  const auto along = [&](int j) {  // the state moved along s on the system at p + o_j h
    const double e = kStencilOffsets[static_cast<std::size_t>(j)] * h;
    return std::pair<VecX, VecX>{init.q + e * sq, init.v + e * sv};
  };
  const auto system = [&](int j) -> const System& { return stencil.daes[static_cast<std::size_t>(j)]->system(); };
  const VecX dg = stencilDerivative<VecX>(h, [&](int j) {
    VecX g;
    evaluateConstraints(system(j), along(j).first, t0, &g, nullptr);
    return g;
  });
  EXPECT_LT(dg.lpNorm<Eigen::Infinity>(), kTolerance);
  const VecX dc = stencilDerivative<VecX>(
      h, [&](int j) { return VecX(velocityConstraintResidual(system(j), along(j).first, along(j).second, t0)); });
  EXPECT_LT(dc.lpNorm<Eigen::Infinity>(), kTolerance);
  // and the whole sensitivity residual F_y s0 + F_y' s0' + F_p at t0 (same difference)
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);
  const VecX dF = stencilDerivative<VecX>(h, [&](int j) {
    const double e = kStencilOffsets[static_cast<std::size_t>(j)] * h;
    const VecX y = y0 + e * s.s0.col(0), yp = yp0 + e * s.sp0.col(0);
    VecX F(dae.size());
    stencil.daes[static_cast<std::size_t>(j)]->residual(t0, y.data(), yp.data(), F.data());
    return F;
  });
  // scaled by the largest |dF/dp| (the reaction forces' scale, ~1 N/m here)
  EXPECT_LT(dF.lpNorm<Eigen::Infinity>(), 1e-6);
  // without the projection the sensitivity would be 0 (the given position does not move)
  EXPECT_GT(sq.lpNorm<Eigen::Infinity>(), 0.5);
}

// ----- scene paths ---------------------------------------------------------------------

// dF/dp from the terms that differ (ResidualDifferences, DaeSystem::residualOfParts): a
// section dimension of the rod takes the rod's terms only, the slider's mass the slider's,
// a joint point that joint's and no body's, a drive speed the driver's only (every one the
// driver's: a term of time); the slider's mass and the joint point are linear (two-point
// difference: a revolute joint's rows are linear in its body-frame points), the section
// height is not (h^3), the drive speed has no term of the state; and the derivative
// equals the five-point difference of the whole residuals to the latter's round-off, kRoundOff sum_j |w_j F_j| / h
// per row (the parts' difference leaves out terms that cancel, so it is the more exact).
TEST(Sensitivities, ParameterDerivativeTakesOnlyTheTermsThatDiffer) {
  constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
  const std::string path = std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json";
  const std::string text = json::parse(readFile(path)).dump();
  const Scene base = parseSceneText(text, path);
  const std::vector<std::string> paths{"bodies[1].section.height", "bodies[2].mass", "joints[1].points[0][0]",
                                       "drivers[0].law.speed"};
  const std::vector<std::vector<std::string>> expectedBodies{{"rod"}, {"slider"}, {}, {}};
  const std::vector<std::vector<std::string>> expectedConstraints{{"motor"}, {"motor"}, {"O2", "motor"}, {"motor"}};
  const std::vector<bool> expectedLinear{false, true, true, false};
  const SensitivityScenes sc = buildSensitivityScenes(text, path, base, paths);
  const DaeSystem dae(base.system, Formulation::Ggl);
  const PerturbedDaes perturbed = perturbedDaes(dae, sc.parameters);
  // a generic state: every entry non-zero
  const int n = dae.size();
  VecX y(n), yp(n);
  for (int k = 0; k < n; ++k) {
    y[k] = 0.3 * std::cos(1.7 * k) + 0.01 * k;
    yp[k] = 0.5 * std::sin(2.3 * k + 0.4);
  }
  ResidualDifferences d(perturbed.stencils, 0.0, y, yp);
  const System& sys = base.system;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    std::vector<std::string> taken;
    for (int b = 0; b < sys.numBodies(); ++b) {
      if (d.parts(static_cast<int>(i)).bodies[static_cast<std::size_t>(b)]) taken.push_back(sys.body(BodyIndex(b)).name());
    }
    EXPECT_EQ(taken, expectedBodies[i]) << paths[i];
    std::vector<std::string> constraints;
    for (int c = 0; c < sys.numConstraints(); ++c) {
      if (d.parts(static_cast<int>(i)).constraints[static_cast<std::size_t>(c)]) {
        constraints.push_back(sys.constraint(ConstraintIndex(c)).name());
      }
    }
    EXPECT_EQ(constraints, expectedConstraints[i]) << paths[i];
    EXPECT_EQ(d.linearTerms(static_cast<int>(i)), expectedLinear[i]) << paths[i];
    VecX dFdp(n);
    const double t = 0.013;
    d.residualDerivative(static_cast<int>(i), t, y.data(), yp.data(), dFdp.data());
    std::array<VecX, kStencilPoints> F;
    for (std::size_t j = 0; j < kStencilPoints; ++j) {
      F[j] = VecX(n);
      perturbed.stencils[i].daes[j]->residual(t, y.data(), yp.data(), F[j].data());
    }
    const double h = sc.parameters[i].step;
    const VecX whole = stencilDerivative<VecX>(h, [&](int j) { return F[static_cast<std::size_t>(j)]; });
    EXPECT_GT(whole.cwiseAbs().maxCoeff(), 0.0) << paths[i] << ": the residual depends on it";
    for (int k = 0; k < n; ++k) {
      double bound = 0.0;
      for (std::size_t j = 0; j < kStencilPoints; ++j) bound += kRoundOff * std::fabs(kStencilWeights[j] * F[j][k]) / h;
      EXPECT_LE(std::fabs(dFdp[k] - whole[k]), bound) << paths[i] << ", row " << k;
    }
  }
}

TEST(ScenePath, ReadsAndSetsNumbersAndNamesWhatIsWrong) {
  json j = json::parse(R"({"bodies": [{"mass": 2, "name": "a"}, {"section": {"area": 1e-4}}], "solver": {"rtol": 1e-8}})");
  EXPECT_EQ(sceneNumber(j, "bodies[0].mass"), 2.0);
  EXPECT_EQ(sceneNumber(j, "bodies[-1].section.area"), 1e-4);
  setSceneNumber(j, "solver.rtol", 1e-6);
  EXPECT_EQ(j["solver"]["rtol"].get<double>(), 1e-6);
  const auto message = [&](const std::string& path) {
    try {
      sceneNumber(j, path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("bodies[2].mass").find("no element [2]"), std::string::npos) << message("bodies[2].mass");
  EXPECT_NE(message("bodies[0].inertia").find("no key 'inertia'"), std::string::npos);
  EXPECT_NE(message("bodies[0].name").find("expected a number"), std::string::npos);
  EXPECT_NE(message("bodies[x].mass").find("is not an index"), std::string::npos);
  EXPECT_NE(message("bodies[0.mass").find("without its ']'"), std::string::npos);
  EXPECT_NE(message("solver..rtol").find("empty name"), std::string::npos);
  EXPECT_NE(message("").find("empty"), std::string::npos);
}

// ----- (e) the command line ------------------------------------------------------------

TEST_F(Cli, SensitivityColumnsAndSummaryGradients) {
  json j = example();
  j["solver"]["t_end"] = 1.0;
  const fs::path scene = writeScene("crank.json", j);
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                          " --quiet --sensitivity 'bodies[2].mass' --sensitivity='joints[2].points[0][0]'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = readFile(dir_ / "out" / "results.csv");
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",dslider.x/dbodies[2].mass,"), std::string::npos);
  EXPECT_NE(header.find(",dmotor.effort/djoints[2].points[0][0]"), std::string::npos);
  const json summary = json::parse(readFile(dir_ / "out" / "summary.json"));
  const json& s = summary.at("sensitivities");
  EXPECT_EQ(s.at("parameters").size(), 2u);
  EXPECT_EQ(s.at("parameters")[0].at("path"), "bodies[2].mass");
  EXPECT_DOUBLE_EQ(s.at("parameters")[0].at("value").get<double>(), 0.5);
  // the final slider position's gradient in the rod length: the closed form at theta = 1 rad
  const double th = 1.0, exact = 2.0 / std::sqrt(4.0 - std::sin(th) * std::sin(th));
  EXPECT_NEAR(s.at("final").at("slider.x").at("gradient").at("joints[2].points[0][0]").get<double>(), exact, 1e-7);
  // the largest |slider.x| is at t = 0 (x = 3), where its gradient in l2 is 1
  EXPECT_NEAR(s.at("max_abs").at("slider.x").at("gradient").at("joints[2].points[0][0]").get<double>(), 1.0, 1e-7);
}

// The scene's "sensitivity" object: its parameters (and adjoint outputs) are what a run
// computes where the command line names none; an option given replaces the scene's list.
TEST_F(Cli, SceneSensitivityKeyIsTheDefaultOfTheOptions) {
  json j = example();
  j["solver"]["t_end"] = 1.0;
  j["sensitivity"] = {{"parameters", {"bodies[2].mass", "joints[2].points[0][0]"}}};
  const fs::path scene = writeScene("crank.json", j);
  const auto runWith = [&](const std::string& options, const std::string& out) {
    return run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / out).string()) + " --quiet " +
               options);
  };
  CliResult r = runWith("", "keyed");
  ASSERT_EQ(r.status, 0) << r.err;
  std::string csv = readFile(dir_ / "keyed" / "results.csv");
  std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",dslider.x/dbodies[2].mass,"), std::string::npos);
  EXPECT_NE(header.find(",dslider.x/djoints[2].points[0][0],"), std::string::npos);
  const json summary = json::parse(readFile(dir_ / "keyed" / "summary.json"));
  // the final slider position's gradient in the rod length: the closed form at theta = 1 rad
  // (as SensitivityColumnsAndSummaryGradients)
  const double th = 1.0, exact = 2.0 / std::sqrt(4.0 - std::sin(th) * std::sin(th));
  EXPECT_NEAR(summary.at("sensitivities").at("final").at("slider.x").at("gradient").at("joints[2].points[0][0]").get<double>(),
              exact, 1e-7);
  // an option replaces the scene's list
  r = runWith("--sensitivity 'bodies[1].mass'", "option");
  ASSERT_EQ(r.status, 0) << r.err;
  csv = readFile(dir_ / "option" / "results.csv");
  header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",dslider.x/dbodies[1].mass,"), std::string::npos);
  EXPECT_EQ(header.find("dbodies[2].mass"), std::string::npos) << header;
  // the scene's adjoint outputs with its parameters
  j["sensitivity"]["adjoint"] = {"integral_square:slider.x"};
  const fs::path adjointScene = writeScene("adjoint.json", j);
  r = run("run " + shellQuote(adjointScene.string()) + " --out " + shellQuote((dir_ / "adjoint").string()) + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const json s = json::parse(readFile(dir_ / "adjoint" / "summary.json")).at("sensitivities");
  EXPECT_EQ(s.at("method"), "adjoint");
  EXPECT_TRUE(s.at("integrals").contains("integral_square:slider.x"));
  // bad input: exit 2 naming the key
  struct Case {
    json key;
    std::string options, expected;
  };
  for (const Case& c :
       {Case{{{"parameters", json::array()}}, "", "sensitivity: key \"parameters\" must list at least one"},
        Case{{{"paramters", {"bodies[2].mass"}}}, "", "sensitivity: unknown key \"paramters\""},
        Case{{{"parameters", {"bodies[2].mass", 3}}}, "", "element [1] must be a dotted scene path"},
        Case{{{"parameters", {"bodies[7].mass"}}}, "", "no element [7]"},
        Case{{{"parameters", {"bodies[2].mass"}}, {"adjoint", {"integral:slider.x"}}, {"error_control", false}}, "",
             "\"error_control\" is for the forward sensitivities"},
        Case{{{"parameters", {"bodies[2].mass"}}, {"adjoint", {"integral:slider.x"}}}, "--no-sensitivity-error-control",
             "option --no-sensitivity-error-control is for the forward sensitivities"}}) {
    json bad = example();
    bad["sensitivity"] = c.key;
    r = run("run " + shellQuote(writeScene("bad.json", bad).string()) + " --out " + shellQuote((dir_ / "bad").string()) +
            " --quiet " + c.options);
    EXPECT_EQ(r.status, 2) << c.key.dump() << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << c.key.dump();
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.key.dump() << ": " << r.err;
  }
}

TEST_F(Cli, SensitivityBadInputExitsTwoNamingTheParameter) {
  const fs::path scene = writeScene("crank.json", example());
  const auto runWith = [&](const std::string& options) {
    return run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) + " --quiet " +
               options);
  };
  struct Case {
    std::string options, expected;
  };
  for (const Case& c : {Case{"--sensitivity 'bodies[7].mass'", "no element [7]"},
                        Case{"--sensitivity 'bodies[0].density'", "no key 'density'"},
                        Case{"--sensitivity 'bodies[0].name'", "expected a number"},
                        Case{"--sensitivity 'solver.formulation'", "expected a number"},
                        Case{"--sensitivity 'bodies[0].mass' --sensitivity 'bodies[0].mass'", "given twice"},
                        Case{"--sensitivity", "needs a scene path"}}) {
    const CliResult r = runWith(c.options);
    EXPECT_EQ(r.status, 2) << c.options << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << c.options;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.options << ": " << r.err;
  }
  // another integrator
  json radau = example();
  radau["solver"]["integrator"] = "radau5";
  const CliResult r = run("run " + shellQuote(writeScene("radau.json", radau).string()) + " --out " +
                          shellQuote((dir_ / "out").string()) + " --quiet --sensitivity 'bodies[0].mass'");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("IDAS only"), std::string::npos) << r.err;
}

TEST_F(Cli, SensitivityOfAStructureChangingParameterExitsTwo) {
  // the number of beam elements of the elastic slider crank: an integer count, its perturbed
  // scene is refused by the reader (and would change the unknowns)
  const json j = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json"));
  const fs::path scene = writeScene("elastic.json", j);
  std::string path;
  for (std::size_t b = 0; b < j["bodies"].size(); ++b) {
    if (j["bodies"][b].contains("beam")) path = "bodies[" + std::to_string(b) + "].beam.elements";
  }
  ASSERT_FALSE(path.empty());
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                          " --quiet --sensitivity '" + path + "'");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("sensitivity parameter '" + path + "'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "results.csv"));
}

}  // namespace
