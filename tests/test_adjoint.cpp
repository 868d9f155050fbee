// Adjoint sensitivities (docs/sensitivities.md, "Adjoint sensitivities"): gradients of
// integral outputs by one forward and one backward run, against a closed form (a
// spring-mass-damper: stiffness, damping, mass and the initial position), against the
// forward sensitivities of the same outputs (a pendulum, the rigid and the elastic slider
// crank), and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "sensitivity_test_support.hpp"
#include "core/errors.hpp"
#include "sensitivity/adjoint_run.hpp"
#include "results/adjoint_results.hpp"
#include "results/results_table.hpp"
#include "scene/scene_path.hpp"
#include "results/sensitivity_results.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

/// An adjoint run of a scene given as JSON: the summary (value and gradient per output).
AdjointSummary adjointRun(const json& scene, const std::vector<std::string>& paths, const std::vector<std::string>& specs) {
  const std::string text = scene.dump();
  Scene base = parseSceneText(text);
  base.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", base, paths);
  return runAdjointScene(base, perturbed, specs, [](const OutputSample&) {});
}

/// The forward gradient of int c dt or int c^2 dt: the forward sensitivities dc/dp
/// (validated against whole runs in test_sensitivities*.cpp) at outputs h apart, an even
/// number of intervals, integrated by Simpson's rule: error h^4 T max|f^(4)| / 180, below
/// 1e-9 of the gradient where h omega <= 0.05 for the response's highest frequency omega.
std::vector<double> forwardGradient(json scene, const std::vector<std::string>& paths, const std::string& column,
                                    bool square, double h) {
  const double T = scene["solver"]["t_end"].get<double>();
  const auto intervals = static_cast<long>(std::llround(T / h));
  EXPECT_EQ(intervals % 2, 0);
  const double step = T / static_cast<double>(intervals);
  scene["solver"]["output_step"] = step;
  const SensitivityRun run = runWithSensitivities(scene, paths);
  EXPECT_TRUE(run.summary.ok) << run.summary.message;
  EXPECT_EQ(run.rows.size(), static_cast<std::size_t>(intervals + 1));
  std::vector<double> out(paths.size(), 0.0);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t r = 0; r < run.rows.size(); ++r) {
      const double w = (r == 0 || r + 1 == run.rows.size()) ? 1.0 : (r % 2 ? 4.0 : 2.0);
      const double f = square ? 2.0 * run.value(r, column) * run.d(r, column, i) : run.d(r, column, i);
      out[i] += w * f * step / 3.0;
    }
  }
  return out;
}

/// The adjoint gradients of KIND:COLUMN equal the forward ones (forwardGradient) to
/// `tolerance` of each.
void expectAdjointEqualsForward(const char* what, const json& scene, const std::vector<std::string>& paths,
                                const std::string& kind, const std::string& column, double h, double tolerance) {
  const std::string spec = kind + ":" + column;
  const AdjointSummary s = adjointRun(scene, paths, {spec});
  ASSERT_TRUE(s.run.ok) << s.run.message;
  ASSERT_TRUE(s.backwardOk) << s.backwardMessage;
  const std::vector<double> forward = forwardGradient(scene, paths, column, kind == "integral_square", h);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const double got = s.outputs[0].gradient[static_cast<Eigen::Index>(i)];
    std::printf("%s d %s / d %s: adjoint %.10g, forward %.10g (relative %.2g)\n", what, spec.c_str(), paths[i].c_str(),
                got, forward[i], std::fabs(got - forward[i]) / std::fabs(forward[i]));
    EXPECT_GT(std::fabs(forward[i]), 0.0) << paths[i];
    EXPECT_NEAR(got, forward[i], tolerance * std::fabs(forward[i])) << what << ": " << paths[i];
  }
}

json exampleScene(const std::string& name) {
  return json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + name));
}

/// examples/slider_crank_rigid.json without its driver, the crank started at 1 rad/s (one
/// degree of freedom, four constraint pairs), over `tEnd` at tolerances rtol, rtol / 100.
json freeCrank(double tEnd, double rtol) {
  json j = exampleScene("slider_crank_rigid.json");
  j.erase("drivers");
  j["bodies"][0]["angular_velocity"] = 1.0;
  j["solver"]["rtol"] = rtol;
  j["solver"]["atol"] = rtol / 100;
  j["solver"]["t_end"] = tEnd;
  return j;
}

}  // namespace

namespace {

// ----- a spring-mass-damper: closed form ------------------------------------------------


/// x(t) = 1 + u0 e^{-zeta wn t} (cos wd t + zeta wn / wd sin wd t) (Meirovitch, Elements of
/// Vibration Analysis, eq. 2.27), complex for the complex-step derivative.
std::complex<double> position(double t, std::complex<double> k, std::complex<double> c, std::complex<double> m,
                              std::complex<double> x0) {
  const std::complex<double> u0 = x0 - 1.0;
  const std::complex<double> wn = std::sqrt(k / m), zeta = c / (2.0 * std::sqrt(k * m));
  const std::complex<double> wd = wn * std::sqrt(1.0 - zeta * zeta);
  return 1.0 + u0 * std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
}

/// int_0^T f(t) dt by composite 5-point Gauss-Legendre quadrature on 600 panels (error below
/// 1e-14 of the integral for the analytic integrands here: a panel holds 1/40 of a period).
template <class F>
std::complex<double> gaussLegendre(double T, F f) {
  const double nodes[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  const double weights[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                             0.2369268850561891};
  const int panels = 600;
  const double h = T / panels;
  std::complex<double> sum = 0.0;
  for (int p = 0; p < panels; ++p) {
    for (int i = 0; i < 5; ++i) sum += 0.5 * h * weights[i] * f(h * (p + 0.5 + 0.5 * nodes[i]));
  }
  return sum;
}

/// int_0^T x^2 dt of the spring-mass-damper (gaussLegendre).
std::complex<double> integralOfSquare(double T, std::complex<double> k, std::complex<double> c, std::complex<double> m,
                                      std::complex<double> x0) {
  return gaussLegendre(T, [&](double t) {
    const std::complex<double> x = position(t, k, c, m, x0);
    return x * x;
  });
}

}  // namespace

TEST(Adjoint, SpringMassDamperIntegralMatchesClosedForm) {
  const std::vector<std::string> paths = {"forces[0].stiffness", "forces[0].damping", "bodies[0].mass",
                                          "bodies[0].position[0]"};
  const AdjointSummary s = adjointRun(springMassDamper(), paths, {"integral_square:mass.x"});
  ASSERT_TRUE(s.run.ok) << s.run.message;
  ASSERT_TRUE(s.backwardOk) << s.backwardMessage;
  ASSERT_EQ(s.outputs.size(), 1u);
  const double k = 50.0, c = 0.8, m = 2.0, x0 = 1.1, T = 3.0, e = 1e-30;
  const std::complex<double> I(0.0, 1.0);
  // G itself: the forward quadrature follows the state's steps at rtol 1e-10
  const double G = std::real(integralOfSquare(T, k, c, m, x0));
  EXPECT_NEAR(s.outputs[0].value, G, 1e-9 * G);
  // complex-step derivatives of the closed form (Squire & Trapp 1998): exact to round-off
  const double exact[4] = {std::imag(integralOfSquare(T, k + I * e, c, m, x0)) / e,
                           std::imag(integralOfSquare(T, k, c + I * e, m, x0)) / e,
                           std::imag(integralOfSquare(T, k, c, m + I * e, x0)) / e,
                           std::imag(integralOfSquare(T, k, c, m, x0 + I * e)) / e};
  // The adjoint is integrated back at rtol 1e-10 with absolute tolerances rtol |G| over the
  // state's scales, the gradients' quadratures to rtol |G| / |p|; dF/dp is exact up to the
  // central difference's round-off (~1e-11). The global error of 14 periods leaves 1e-6 of
  // each derivative (measured: see the printout).
  const double kRelativeTolerance = 1e-6;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const double got = s.outputs[0].gradient[static_cast<Eigen::Index>(i)];
    std::printf("spring-mass-damper dG/d%s: adjoint %.12g, closed form %.12g (relative %.2g)\n", paths[i].c_str(), got,
                exact[i], std::fabs(got - exact[i]) / std::fabs(exact[i]));
    EXPECT_NEAR(got, exact[i], kRelativeTolerance * std::fabs(exact[i])) << paths[i];
  }
}



TEST(Adjoint, KsAggregateMatchesClosedForm) {
  // The spring-mass-damper's KS aggregate of x over 3 s, ln(int exp(rho x) dt / T) / rho with
  // rho = 20 / m (a smooth maximum: within ln(T ...) / rho of max x = 1.1 m), and its
  // gradient: the complex-step derivative of the same function of the Gauss-Legendre
  // integral. Its error: that of int exp(rho x) dt, relative (as SpringMassDamper...).
  const std::vector<std::string> paths = {"forces[0].stiffness", "forces[0].damping", "bodies[0].position[0]"};
  const AdjointSummary s = adjointRun(springMassDamper(), paths, {"ks:mass.x:20"});
  ASSERT_TRUE(s.backwardOk) << s.backwardMessage;
  const double rho = 20.0, T = 3.0, e = 1e-30;
  const std::complex<double> I(0.0, 1.0);
  const auto ks = [&](std::complex<double> k, std::complex<double> c, std::complex<double> x0) {
    const std::complex<double> sum =
        gaussLegendre(T, [&](double t) { return std::exp(rho * position(t, k, c, 2.0, x0)); });
    return std::log(sum / T) / rho;
  };
  const double k = 50.0, c = 0.8, x0 = 1.1;
  EXPECT_NEAR(s.outputs[0].value, std::real(ks(k, c, x0)), 1e-9);
  EXPECT_GT(s.outputs[0].value, 1.0);  // near the largest x, 1.1
  EXPECT_LT(s.outputs[0].value, 1.1);
  const double exact[3] = {std::imag(ks(k + I * e, c, x0)) / e, std::imag(ks(k, c + I * e, x0)) / e,
                           std::imag(ks(k, c, x0 + I * e)) / e};
  const double kRelativeTolerance = 1e-6;  // as SpringMassDamperIntegralMatchesClosedForm
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const double got = s.outputs[0].gradient[static_cast<Eigen::Index>(i)];
    std::printf("spring-mass-damper dKS/d%s: adjoint %.12g, closed form %.12g (relative %.2g)\n", paths[i].c_str(), got,
                exact[i], std::fabs(got - exact[i]) / std::fabs(exact[i]));
    EXPECT_NEAR(got, exact[i], kRelativeTolerance * std::fabs(exact[i])) << paths[i];
  }
}

/// The adjoint gradient of final:COLUMN equals the forward sensitivity of the column at
/// the last row, to `tolerance` of each (or of the largest, for a derivative near zero).
void expectTerminalEqualsForward(const char* what, const json& scene, const std::vector<std::string>& paths,
                                 const std::string& column, double tolerance) {
  const AdjointSummary s = adjointRun(scene, paths, {"final:" + column});
  ASSERT_TRUE(s.run.ok) << s.run.message;
  ASSERT_TRUE(s.backwardOk) << s.backwardMessage;
  const SensitivityRun forward = runWithSensitivities(scene, paths);
  ASSERT_TRUE(forward.summary.ok) << forward.summary.message;
  const std::size_t last = forward.rows.size() - 1;
  // the two runs take their own steps: their values at T agree to the state's error
  EXPECT_NEAR(s.outputs[0].value, forward.value(last, column), 1e-7 * (1.0 + std::fabs(forward.value(last, column))));
  double largest = 0.0;
  for (std::size_t i = 0; i < paths.size(); ++i) largest = std::max(largest, std::fabs(forward.d(last, column, i)));
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const double got = s.outputs[0].gradient[static_cast<Eigen::Index>(i)], expected = forward.d(last, column, i);
    std::printf("%s d final(%s) / d %s: adjoint %.10g, forward %.10g (relative %.2g)\n", what, column.c_str(),
                paths[i].c_str(), got, expected, std::fabs(got - expected) / std::max(std::fabs(expected), 1e-300));
    EXPECT_NEAR(got, expected, tolerance * std::max(std::fabs(expected), 1e-3 * largest)) << what << ": " << paths[i];
  }
}

TEST(Adjoint, TerminalOutputsEqualForwardSensitivities) {
  // final:COLUMN, the column's value at T: its adjoint starts from E^T lambda(T) = c_y on the
  // consistent states (terminalAdjoint), with the constraint rows' part nu^T F_p(T). Against
  // the forward sensitivities at the last row, at the runs' tolerances (both ~1e-8 of the
  // derivatives at these rtol; 1e-6 holds them).
  const double kTolerance = 1e-6;
  expectTerminalEqualsForward("spring-mass-damper", springMassDamper(),
                              {"forces[0].stiffness", "forces[0].damping", "bodies[0].position[0]"}, "mass.x",
                              kTolerance);
  expectTerminalEqualsForward("pendulum", pendulum(), {"joints[0].points[1][1]", "bodies[0].inertia", "bodies[0].angle"},
                              "bob.theta", kTolerance);
  expectTerminalEqualsForward("pendulum", pendulum(), {"joints[0].points[1][1]", "bodies[0].angle"}, "bob.x_dot",
                              kTolerance);
  expectTerminalEqualsForward("free crank", freeCrank(3.0, 1e-11),
                              {"joints[1].points[0][0]", "joints[2].points[0][0]", "bodies[2].mass",
                               "bodies[0].angular_velocity"},
                              "slider.x", kTolerance);
  // the elastic crank (2 nodal elements, 5 ms, rtol 1e-9): M(q) moves, so (dE/dt)^T lambda
  // and the rates of F_y enter the terminal values; the deflection at T by E and the height
  json elastic = exampleScene("slider_crank_elastic.json");
  elastic["bodies"][1]["beam"]["elements"] = 2;
  elastic["solver"]["rtol"] = 1e-9;
  elastic["solver"]["atol"] = 1e-11;
  elastic["solver"]["t_end"] = 0.005;
  const double kElasticTolerance = 1e-5;  // the runs' errors at rtol 1e-9 over a bending period
  expectTerminalEqualsForward("elastic crank", elastic, {"bodies[1].section.youngs_modulus", "bodies[1].section.height"},
                              "mid.uy", kElasticTolerance);
}

TEST(Adjoint, PendulumIntegralEqualsForwardGradient) {
  // A bob on a massless length L = 0.8 m released at 0.3 rad (tests/test_sensitivities.cpp):
  // one constraint pair, so the adjoint multipliers and their terminal values take part.
  // int theta^2 over 2 s with respect to L, the bob's inertia, the release angle.
  const json j = pendulum();
  // Both integrated at rtol 1e-11 over ~1 period: their global errors ~1e-9 of the
  // gradient; Simpson at h = 5e-4 s (omega = 3.5 rad/s) adds 1e-13. 1e-7 holds both.
  const double kTolerance = 1e-7;
  expectAdjointEqualsForward("pendulum", j, {"joints[0].points[1][1]", "bodies[0].inertia", "bodies[0].angle"},
                             "integral_square", "bob.theta", 5e-4, kTolerance);
}

TEST(Adjoint, ARunThatOutgrowsItsRecordingIsRecordedAgain) {
  // The free slider crank (below) with a recording store of 100 steps: the run outgrows it
  // (IDAS makes more checkpoints, whose recomputation is not safe), so it is recorded once
  // more from t0 in one store. The same gradients as with a store that holds the run: the
  // second recording takes its own steps, so the two differ at the state's error (rtol
  // 1e-10): 1e-7 of each gradient.
  const json j = freeCrank(3.0, 1e-10);
  const std::vector<std::string> paths = {"joints[2].points[0][0]", "bodies[2].mass", "bodies[0].angular_velocity"};
  const std::string text = j.dump();
  Scene base = parseSceneText(text);
  base.solver.progress = false;
  const SensitivityScenes perturbed = buildSensitivityScenes(text, "<scene>", base, paths);
  const std::vector<IntegralOutput> outputs{integralOutput("integral_square:slider.x", base, perturbed)};
  const auto none = [](const OutputSample&) {};
  const AdjointSummary one = simulateWithAdjoint(base.system, perturbed.parameters, outputs, base.solver, none);
  const AdjointSummary again = simulateWithAdjoint(base.system, perturbed.parameters, outputs, base.solver, none, 100);
  ASSERT_TRUE(one.backwardOk) << one.backwardMessage;
  ASSERT_TRUE(again.backwardOk) << again.backwardMessage;
  EXPECT_FALSE(one.recordedAgain);
  EXPECT_TRUE(again.recordedAgain);
  EXPECT_GT(one.run.stats.steps, 200);
  const double kTolerance = 1e-7;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const double a = one.outputs[0].gradient[static_cast<Eigen::Index>(i)];
    const double b = again.outputs[0].gradient[static_cast<Eigen::Index>(i)];
    std::printf("recorded again d G / d %s: %.12g, one recording %.12g (relative %.2g)\n", paths[i].c_str(), b, a,
                std::fabs(a - b) / std::fabs(a));
    EXPECT_NEAR(b, a, kTolerance * std::fabs(a)) << paths[i];
  }
}

TEST(Adjoint, FreeSliderCrankIntegralEqualsForwardGradient) {
  // examples/slider_crank_rigid.json without its driver, the crank started at 1 rad/s: one
  // degree of freedom, four constraint pairs. int slider.x^2 dt over 3 s with respect to the
  // crank and rod lengths (joint points: in the constraints), the slider's mass (in the
  // dynamics) and the crank's initial speed (an initial condition: through s(t0)).
  const json j = freeCrank(3.0, 1e-11);
  const double kTolerance = 1e-7;  // as the pendulum's (the crank turns at about 1 rad/s)
  expectAdjointEqualsForward("free crank", j,
                             {"joints[1].points[0][0]", "joints[2].points[0][0]", "bodies[2].mass",
                              "bodies[0].angular_velocity"},
                             "integral_square", "slider.x", 1e-3, kTolerance);
}

TEST(Adjoint, DrivenMechanismWarnsOfItsAlgebraicAdjoint) {
  // The rigid slider crank with its driver has no degree of freedom: its adjoint is all
  // algebraic (lambda_q = lambda_v = 0), IDAS's error estimates vanish and its backward steps
  // stay at order 1: measured errors 6e-3, 6e-4, 6e-5 of d int slider.x^2 / d l1 at rtol
  // 1e-7, 1e-9, 1e-11 (against the closed form 0.2836575884). The run says so.
  json j = exampleScene("slider_crank_rigid.json");
  j["solver"]["t_end"] = 3.0;
  const AdjointSummary s = adjointRun(j, {"joints[1].points[0][0]"}, {"integral_square:slider.x"});
  ASSERT_TRUE(s.run.ok) << s.run.message;
  bool warned = false;
  for (const std::string& w : s.run.warnings) warned = warned || w.find("no degree of freedom") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Adjoint, ElasticSliderCrankIntegralEqualsForwardGradient) {
  // examples/slider_crank_elastic.json with 2 nodal elements over 5 ms (a bending period),
  // rtol 1e-9: M(q) of the rod changes with its angle and deflection, so the adjoint's
  // (dE/dt)^T lambda term takes part. int mid.uy^2 dt with respect to the rod's Young's
  // modulus and section height and the slider's mass.
  json j = exampleScene("slider_crank_elastic.json");
  j["bodies"][1]["beam"]["elements"] = 2;
  j["solver"]["rtol"] = 1e-9;
  j["solver"]["atol"] = 1e-11;
  j["solver"]["t_end"] = 0.005;
  // Both at rtol 1e-9 over one bending period: global errors ~1e-7 of the gradient;
  // Simpson at h = 5e-6 s resolves the rod's axial vibration too (at 2e-5 s the forward
  // gradient by the slider's mass was 2e-4 off; measured 1e-9 of E's and h's at 5e-6 s).
  const double kTolerance = 1e-6;
  expectAdjointEqualsForward("elastic crank", j, {"bodies[1].section.youngs_modulus", "bodies[1].section.height"},
                             "integral_square", "mid.uy", 5e-6, kTolerance);
  // The slider's mass moves the deflection by 3e-3 of |G| / m only, so the state's errors
  // weigh ~300 times more in it: the adjoint's gradient moved by 1e-5 between rtol 1e-8
  // and 1e-10, and the forward sensitivities by it are accurate to 1e-5
  // (NodalRodMatchesWholeRuns). 5e-5 holds both.
  const double kSliderTolerance = 5e-5;
  expectAdjointEqualsForward("elastic crank", j, {"bodies[2].mass"}, "integral_square", "mid.uy", 5e-6,
                             kSliderTolerance);
}

// ----- the command line ------------------------------------------------------------------

TEST_F(Cli, AdjointGradientsInTheSummary) {
  // the free slider crank (FreeSliderCrankIntegralEqualsForwardGradient) over 1 s: two
  // outputs, two parameters; the gradients equal those of the library call to round-off
  const json j = freeCrank(1.0, 1e-8);  // the example's tolerances
  const fs::path scene = writeScene("crank.json", j);
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                          " --quiet --sensitivity 'bodies[2].mass' --sensitivity 'joints[2].points[0][0]'"
                          " --adjoint integral_square:slider.x --adjoint=integral:crank.theta_dot");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = readFile(dir_ / "out" / "results.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')).find("/d"), std::string::npos);  // no derivative columns
  const json s = json::parse(readFile(dir_ / "out" / "summary.json")).at("sensitivities");
  EXPECT_EQ(s.at("method"), "adjoint");
  EXPECT_TRUE(s.at("backward_ok").get<bool>());
  const AdjointSummary direct = adjointRun(j, {"bodies[2].mass", "joints[2].points[0][0]"},
                                           {"integral_square:slider.x", "integral:crank.theta_dot"});
  ASSERT_EQ(direct.outputs.size(), 2u);
  for (const IntegralGradient& g : direct.outputs) {
    const json& out = s.at("integrals").at(g.name);
    EXPECT_DOUBLE_EQ(out.at("value").get<double>(), g.value) << g.name;
    EXPECT_DOUBLE_EQ(out.at("gradient").at("bodies[2].mass").get<double>(), g.gradient[0]) << g.name;
    EXPECT_DOUBLE_EQ(out.at("gradient").at("joints[2].points[0][0]").get<double>(), g.gradient[1]) << g.name;
  }
  // int theta_dot dt = theta(1) - theta(0): the forward quadrature follows the state's steps
  // (rtol 1e-8 of the example): 1e-6 rad holds it
  const ResultsTable table = readResults(dir_ / "out");
  const int theta = table.column("crank.theta");
  ASSERT_GE(theta, 0);
  EXPECT_NEAR(s.at("integrals").at("integral:crank.theta_dot").at("value").get<double>(),
              table.rows.back()[static_cast<std::size_t>(theta)] - table.rows.front()[static_cast<std::size_t>(theta)],
              1e-6);
}

TEST_F(Cli, AdjointBadInputExitsTwoNamingTheOutput) {
  const fs::path scene = writeScene("crank.json", exampleScene("slider_crank_rigid.json"));
  const auto runWith = [&](const std::string& options) {
    return run("run " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) + " --quiet " +
               options);
  };
  struct Case {
    std::string options, expected;
  };
  for (const Case& c : {Case{"--adjoint integral:slider.x", "needs the parameters"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint maximum:slider.x", "expected KIND:COLUMN"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint ks:slider.x", "RHO a positive number"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint ks:slider.x:-1", "RHO a positive number"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint integral:slider.z", "no results column \"slider.z\""},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint integral:motor.effort", "multipliers"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint integral:slider.x_ddot", "accelerations"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint", "needs an integral output"},
                        Case{"--sensitivity 'bodies[2].mass' --adjoint integral:slider.x --no-sensitivity-error-control",
                             "not with adjoint outputs (--adjoint)"}}) {
    const CliResult r = runWith(c.options);
    EXPECT_EQ(r.status, 2) << c.options << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << c.options;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.options << ": " << r.err;
  }
  json index3 = exampleScene("slider_crank_rigid.json");
  index3["solver"]["formulation"] = "index3";
  const CliResult r = run("run " + shellQuote(writeScene("index3.json", index3).string()) + " --out " +
                          shellQuote((dir_ / "out").string()) +
                          " --quiet --sensitivity 'bodies[2].mass' --adjoint integral:slider.x");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("GGL"), std::string::npos) << r.err;
}
