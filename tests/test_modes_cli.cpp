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
