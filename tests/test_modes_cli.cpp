// flexmbd modes (app/modes_command.cpp): the files it writes, the Campbell sweep and
// its errors (exit status 2, one line naming the key, option or driver).
#include "cli_fixture.hpp"

#include <cmath>

namespace {

/// A uniform rod (mass 2, length 0.8) hanging from a revolute joint at the origin.
nlohmann::json rodPendulum() {
  return nlohmann::json::parse(R"({"name": "rod pendulum", "gravity": [0, -9.81],
    "bodies": [{"name": "rod", "type": "rigid", "mass": 2, "inertia": 0.10666666666666667, "com": [0.4, 0],
                "angle": -1.5707963267948966}],
    "joints": [{"name": "O", "type": "revolute", "bodies": ["ground", "rod"], "points": [[0, 0], [0, 0]]}],
    "solver": {"t_end": 1}})");
}

/// A flexible beam (8 elements, clamped at its hub end) turned by a constant-speed driver.
nlohmann::json rotatingBeam() {
  return nlohmann::json::parse(R"({"name": "rotating beam",
    "bodies": [{"name": "blade", "type": "flexible",
                "section": {"width": 0.02, "height": 0.01, "youngs_modulus": 2e11, "density": 7800},
                "beam": {"length": 1.0, "elements": 8}, "reference": {"type": "clamped"}}],
    "joints": [{"name": "hub", "type": "revolute", "bodies": ["ground", "blade"], "points": [[0, 0], [0, 0]]}],
    "drivers": [{"name": "motor", "type": "joint_angle", "joint": "hub", "law": {"type": "constant_speed", "speed": 1.0}}],
    "solver": {"t_end": 1}})");
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace

TEST_F(Cli, ModesWritesTheFrequencyTableShapesAndVtk) {
  const fs::path scene = writeScene("pendulum.json", rodPendulum());
  const fs::path out = dir_ / "out";
  const CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> modes = lines(readFile(out / "modes.csv"));
  ASSERT_EQ(modes.size(), 2u);  // header and the one degree of freedom
  EXPECT_EQ(modes[0], "index,frequency_hz,omega_rad_s,damping_ratio,real,imag");
  // omega = sqrt(3 g / (2 L)); the CSV's 12 digits
  const double omega = std::stod(modes[1].substr(modes[1].find(',', 2) + 1));
  EXPECT_NEAR(omega, std::sqrt(3 * 9.81 / 1.6), 1e-9);
  const std::vector<std::string> shapes = lines(readFile(out / "mode_shapes.csv"));
  ASSERT_EQ(shapes.size(), 4u);  // header, x_dot, y_dot, theta_dot
  EXPECT_EQ(shapes[0], "velocity,mode_1");
  EXPECT_TRUE(fs::exists(out / "vtk" / "mode_01.pvd"));
  EXPECT_NE(r.out.find("mode"), std::string::npos);
}

TEST_F(Cli, ModesPrintsTheBeamModelsNaturalFrequenciesAndSweepsADriver) {
  const fs::path scene = writeScene("blade.json", rotatingBeam());
  const fs::path out = dir_ / "out";
  const CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) +
                          " --count 3 --sweep motor:0:100:3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("beam \"blade\": natural frequencies"), std::string::npos) << r.out;
  const std::vector<std::string> rows = lines(readFile(out / "campbell.csv"));
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], "speed,f1_hz,f2_hz,f3_hz,zeta1,zeta2,zeta3");
  EXPECT_TRUE(fs::exists(out / "campbell.png"));
}

TEST_F(Cli, ModesOfTheShippedBladeGiveTheTableOfDocsModes) {
  // docs/modes.md shows this command on examples/modes_blade.json and its Campbell table;
  // the table is printed to 5 significant digits, so each frequency is checked to 5e-5
  // relative (the doc's rounding).
  const fs::path out = dir_ / "out";
  const CliResult r = run("modes " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/modes_blade.json") + " --out " +
                          shellQuote(out.string()) + " --count 3 --steady --sweep motor:0:60:4");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::vector<double>> doc = {{8.1799, 51.267, 143.62},
                                                {8.2996, 51.813, 144.23},
                                                {8.6339, 53.418, 146.01},
                                                {9.1235, 55.993, 148.94}};
  const std::vector<std::string> rows = lines(readFile(out / "campbell.csv"));
  ASSERT_EQ(rows.size(), 5u);
  for (int i = 0; i < 4; ++i) {
    std::istringstream in(rows[i + 1]);
    std::string field;
    std::getline(in, field, ',');  // speed
    for (int k = 0; k < 3; ++k) {
      std::getline(in, field, ',');
      EXPECT_NEAR(std::stod(field) / doc[i][k], 1.0, 5e-5) << "speed row " << i << ", mode " << k + 1;
    }
  }
}

TEST_F(Cli, ModesBadInputExitsWith2NamingTheKey) {
  nlohmann::json j = rodPendulum();
  j["bodies"][0]["masss"] = 1.0;
  const fs::path scene = writeScene("bad.json", j);
  CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("masss"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "modes.csv"));

  const fs::path good = writeScene("good.json", rodPendulum());
  r = run("modes " + shellQuote(good.string()) + " --out " + shellQuote((dir_ / "out").string()) + " --count 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--count"), std::string::npos) << r.err;

  r = run("modes " + shellQuote(good.string()) + " --out " + shellQuote((dir_ / "out").string()) + " --sweep nosuch:0:1:3");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("\"nosuch\""), std::string::npos) << r.err;

  r = run("modes " + shellQuote(good.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
}

namespace {

/// omega_rad_s of each row of modes.csv.
std::vector<double> omegas(const fs::path& csv) {
  std::vector<double> out;
  const std::vector<std::string> rows = lines(readFile(csv));
  for (size_t k = 1; k < rows.size(); ++k) {
    const size_t c1 = rows[k].find(','), c2 = rows[k].find(',', c1 + 1);
    out.push_back(std::stod(rows[k].substr(c2 + 1)));
  }
  return out;
}

}  // namespace

TEST_F(Cli, ModesOfSpatialScenesWithoutAtAreTakenAboutTheStaticEquilibrium) {
  // 1. A rigid arm on a revolute joint about world y, started at rest 1.2 rad off the
  // bottom: the modes are those of the hanging equilibrium, omega = sqrt(m g d / I_pivot)
  // with I_pivot = Iyy + m d^2 (compound pendulum); exact to round-off, the CSV's 12 digits.
  const double m = 3.0, d = 0.35, iyy = 0.08, angle = 1.2, g = 9.81;
  const nlohmann::json pendulum = {
      {"name", "spatial pendulum"}, {"dimension", 3}, {"gravity", {0, 0, -g}},
      {"bodies", {{{"name", "arm"}, {"type", "rigid"}, {"mass", m}, {"inertia", {0.05, iyy, 0.04}},
                   {"position", {-d * std::sin(angle), 0, -d * std::cos(angle)}},
                   {"orientation", {{"axis", {0, 1, 0}}, {"angle", angle}}}}}},
      {"joints", {{{"name", "pivot"}, {"type", "revolute"}, {"bodies", {"ground", "arm"}},
                   {"frames", {{{"point", {0, 0, 0}}, {"axis", {0, 1, 0}}}, {{"point", {0, 0, d}}, {"axis", {0, 1, 0}}}}}}}},
      {"solver", {{"t_end", 1}}}};
  const fs::path scene = writeScene("spatial_pendulum.json", pendulum);
  const fs::path out = dir_ / "pendulum";
  CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<double> w = omegas(out / "modes.csv");
  ASSERT_EQ(w.size(), 1u);  // one degree of freedom
  EXPECT_NEAR(w[0] / std::sqrt(m * g * d / (iyy + m * d * d)), 1.0, 1e-10);
  EXPECT_NE(r.out.find("at rest"), std::string::npos) << r.out;

  // the same arm on its revolute joint twice: by default ("redundant_constraints":
  // "resolve", as a run) the repeated equations are released and the modes are the same;
  // with "refuse" exit status 2 naming the repeated joint
  nlohmann::json doubled = pendulum;
  doubled["joints"].push_back(doubled["joints"][0]);
  doubled["joints"][1]["name"] = "again";
  const fs::path doubledScene = writeScene("doubled.json", doubled);
  r = run("modes " + shellQuote(doubledScene.string()) + " --out " + shellQuote((dir_ / "doubled").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  w = omegas(dir_ / "doubled" / "modes.csv");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(w[0] / std::sqrt(m * g * d / (iyy + m * d * d)), 1.0, 1e-10);
  doubled["solver"]["redundant_constraints"] = "refuse";
  const fs::path refused = writeScene("refused.json", doubled);
  r = run("modes " + shellQuote(refused.string()) + " --out " + shellQuote((dir_ / "refused").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("joint 'again'"), std::string::npos) << r.err;

  // 2. A spatial steel cantilever (8 elements, square 20 mm section, L = 1.2 m) sagging
  // under its weight: its two lowest modes are the Euler-Bernoulli clamped-free
  // (beta_1 L)^2 sqrt(EI / (rho A L^4)), beta_1 L = 1.87510407, in both bending planes
  // (cubic elements, h^4: 2.1e-6 with 8 elements; 1e-5 bounds it).
  const double L = 1.2, side = 0.02, E = 2.1e11, rho = 7850.0;
  const nlohmann::json beam = {
      {"name", "cantilever"}, {"dimension", 3}, {"gravity", {0, 0, -g}},
      {"bodies", {{{"name", "beam"}, {"type", "flexible"},
                   {"section", {{"width", side}, {"height", side}, {"youngs_modulus", E}, {"poisson_ratio", 0.3}, {"density", rho}}},
                   {"beam", {{"length", L}, {"elements", 8}}}, {"reference", {{"type", "clamped"}}}}}},
      {"joints", {{{"name", "root"}, {"type", "fixed"}, {"bodies", {"ground", "beam"}},
                   {"frames", {{{"point", {0, 0, 0}}}, {{"point", {0, 0, 0}}}}}}}},
      {"solver", {{"t_end", 1}}}};
  const fs::path beamScene = writeScene("spatial_cantilever.json", beam);
  const fs::path beamOut = dir_ / "cantilever";
  r = run("modes " + shellQuote(beamScene.string()) + " --out " + shellQuote(beamOut.string()) + " --count 3");
  ASSERT_EQ(r.status, 0) << r.err;
  w = omegas(beamOut / "modes.csv");
  ASSERT_EQ(w.size(), 3u);
  const double I = std::pow(side, 4) / 12, A = side * side, beta1L = 1.87510407;
  const double exact = beta1L * beta1L * std::sqrt(E * I / (rho * A * std::pow(L, 4)));
  EXPECT_NEAR(w[0] / exact, 1.0, 1e-5);
  EXPECT_NEAR(w[1] / exact, 1.0, 1e-5);
  EXPECT_TRUE(fs::exists(beamOut / "vtk" / "mode_01.pvd"));
}

namespace {

/// Four sliders of mass 1 on prismatic joints, each with a damper of c = 1e-3 to ground and
/// no spring: s = 0 and s = -c / m = -1e-3 per slider, the sparse solver's default shift.
nlohmann::json dampedSliders() {
  nlohmann::json j = {{"name", "damped sliders"}, {"bodies", nlohmann::json::array()},
                      {"joints", nlohmann::json::array()}, {"forces", nlohmann::json::array()},
                      {"solver", {{"t_end", 1}}}};
  for (int i = 0; i < 4; ++i) {
    const std::string k = std::to_string(i);
    const double y = i;
    j["bodies"].push_back({{"name", "slider" + k}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", 0.1},
                           {"com", {0, 0}}, {"position", {0.0, y}}, {"angle", 0.0}});
    j["joints"].push_back({{"name", "P" + k}, {"type", "prismatic"}, {"bodies", {"ground", "slider" + k}},
                           {"points", {{0.0, y}, {0, 0}}}, {"axis", {1.0, 0.0}}});
    j["forces"].push_back({{"name", "damper" + k}, {"type", "spring_damper"}, {"bodies", {"ground", "slider" + k}},
                           {"points", {{1.0, y}, {0, 0}}}, {"stiffness", 0.0}, {"damping", 1e-3}});
  }
  return j;
}

/// damping_ratio of each row of modes.csv.
std::vector<double> dampingRatios(const fs::path& csv) {
  std::vector<double> out;
  const std::vector<std::string> rows = lines(readFile(csv));
  for (size_t k = 1; k < rows.size(); ++k) {
    size_t c = 0;
    for (int field = 0; field < 3; ++field) c = rows[k].find(',', c) + 1;
    out.push_back(std::stod(rows[k].substr(c)));
  }
  return out;
}

}  // namespace

// An eigensolver that does not converge is a solver failure (exit 1, as a run
// whose integrator fails), not bad input (exit 2): the scene is well formed and the dense
// solver finds the modes. Forced by an eigenvalue at the shift (the operator
// (A - sigma E)^-1 E is then singular to rounding: 4e21 against the other eigenvalues' 1e3).
TEST_F(Cli, ModesEigensolverFailureExitsWith1AndTheDenseSolverFindsTheModes) {
  const fs::path scene = writeScene("dampers.json", dampedSliders());
  const fs::path out = dir_ / "out";
  CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) +
                    " --solver sparse --count 2");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("dampers.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sparse eigensolver"), std::string::npos) << r.err;  // what failed
  EXPECT_NE(r.err.find("--solver dense"), std::string::npos) << r.err;      // what to do
  EXPECT_FALSE(fs::exists(out / "modes.csv"));

  r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) + " --solver dense --count 8");
  ASSERT_EQ(r.status, 0) << r.err;
  // the real eigenvalue s = -c / m of each slider: omega = |s| = 1e-3, damping ratio 1;
  // the dense solver's rounding on the 8 x 8 first-order matrix scaled to |s| ~ 1e-3 is
  // ~1e-16 relative, the CSV holds 12 digits
  const std::vector<double> w = omegas(out / "modes.csv"), zeta = dampingRatios(out / "modes.csv");
  ASSERT_EQ(w.size(), zeta.size());
  int damped = 0;
  for (size_t k = 0; k < w.size(); ++k) {
    if (w[k] == 0.0) continue;  // the free motions (s = 0)
    EXPECT_NEAR(w[k] / 1e-3, 1.0, 1e-10) << k;
    EXPECT_NEAR(zeta[k], 1.0, 1e-10) << k;
    ++damped;
  }
  EXPECT_EQ(damped, 4);
}

// The sparse solver's Krylov subspace for 4 modes of the spatial elastic slider
// crank (48 independent coordinates) held 21 vectors and did not converge (exit 2 then);
// with 22 (an even basis, analysis/linearization.cpp) it converges, to the dense
// solver's eigenvalues.
TEST_F(Cli, ModesSparseSolverConvergesOnTheSpatialElasticSliderCrank) {
  const std::string scene = shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json");
  const fs::path sparse = dir_ / "sparse", dense = dir_ / "dense";
  CliResult r = run("modes " + scene + " --out " + shellQuote(sparse.string()) + " --solver sparse --count 4");
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("modes " + scene + " --out " + shellQuote(dense.string()) + " --solver dense --count 4");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<double> ws = omegas(sparse / "modes.csv"), wd = omegas(dense / "modes.csv");
  ASSERT_EQ(ws.size(), 4u);
  ASSERT_EQ(wd.size(), 4u);
  // two algorithms in two bases (coordinate partitioning, SVD) on the same linearisation:
  // equal to the sparse solver's tolerance, 1e-10 of each Ritz value, times the condition
  // of the eigenvalues of the damped, non-normal first-order form (the dense solver's
  // rounding, 2e-16 x the largest |s| 1.7e6 rad/s, is 7e-13 of 573 rad/s); measured 2e-11
  constexpr double kSolverAgreement = 1e-8;
  for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(ws[k] / wd[k], 1.0, kSolverAgreement) << k;
}

// A section damping beta of 1e6 s made every mode overdamped by far: the slow
// eigenvalues (~ -1/beta) fell below the zero threshold and were printed as 0 Hz modes
// (exit 0; before that, "the reduced mass matrix is not positive definite"). Now the run
// says the damping dominates, by how much, and what to do; exit 1 (a solver limit).
TEST_F(Cli, ModesWithDampingBeyondTheSolversResolutionSaySo) {
  nlohmann::json scene = nlohmann::json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/modes_blade.json"));
  for (auto& b : scene["bodies"]) {
    if (b["type"] == "flexible") b["section"]["damping"] = 1e6;
  }
  const fs::path p = writeScene("damped.json", scene);
  const CliResult r = run("modes " + shellQuote(p.string()) + " --out " + shellQuote((dir_ / "m").string()) + " --count 3");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("the damping dominates the stiffness"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lower the damping"), std::string::npos) << r.err;
  // beta = 1e-3 s: the top mesh mode (8e4 rad/s) overdamped by beta omega = 80 < 1e3, resolved;
  // the first mode (8.18 Hz) keeps its frequency (damping ratio beta omega / 2 = 0.026)
  for (auto& b : scene["bodies"]) {
    if (b["type"] == "flexible") b["section"]["damping"] = 1e-3;
  }
  const fs::path q = writeScene("light.json", scene);
  const CliResult ok = run("modes " + shellQuote(q.string()) + " --out " + shellQuote((dir_ / "c").string()) + " --count 3");
  ASSERT_EQ(ok.status, 0) << ok.err;
  const std::vector<double> w = omegas(dir_ / "c" / "modes.csv");
  ASSERT_FALSE(w.empty());
  EXPECT_GT(w.back(), 0.0);  // not the spurious zero modes of the refused case
}
