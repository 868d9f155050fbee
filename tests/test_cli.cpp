// Unit tests of the command line (app/flexmbd_main.cpp): exit status, the one-line
// error on stderr, and the files left in the output directory. The binary is run
// through the shell (std::system) in a fresh temporary directory per test.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <hdf5.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"

namespace fs = std::filesystem;

namespace {

TEST_F(Cli, HelpAndVersion) {
  CliResult r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("flexmbd run SCENE.json --out DIR"), std::string::npos) << r.out;
  r = run("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out.rfind("flexmbd ", 0), 0u) << r.out;
}

// `run` simulates planar and spatial multibody models and tensegrity
// structures; its paragraph of the help (also `run --help`) must say so, not "planar".
TEST_F(Cli, HelpDescribesRunAsPlanarAndSpatial) {
  for (const std::string& command : {"--help", "run --help"}) {
    const CliResult r = run(command);
    ASSERT_EQ(r.status, 0) << command;
    const auto start = r.out.find("run simulates");
    ASSERT_NE(start, std::string::npos) << command << ":\n" << r.out;
    const std::string paragraph = r.out.substr(start, r.out.find("\n\n", start) - start);
    for (const char* word : {"planar", "spatial", "flexible", "tensegrity"}) {
      EXPECT_NE(paragraph.find(word), std::string::npos) << command << ": no \"" << word << "\" in\n" << paragraph;
    }
    EXPECT_EQ(r.out.find("planar multibody model"), std::string::npos) << command << ":\n" << r.out;  // the old wording
  }
}

TEST_F(Cli, UnknownKeyInSceneExitsWith2AndNoResults) {
  nlohmann::json j = example();
  j["bodies"][1]["masss"] = 1.0;
  const fs::path scene = writeScene("bad.json", j);
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  std::ofstream(out / "results.csv") << "stale\n";  // from an earlier run: must go
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("masss"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bodies[1]"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
  ASSERT_TRUE(fs::exists(out / "summary.json"));
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
  EXPECT_NE(summary.at("message").get<std::string>().find("masss"), std::string::npos);
}

TEST_F(Cli, MissingSceneFileExitsWith2) {
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote((dir_ / "no_such_scene.json").string()) + " --out " +
                          shellQuote(out.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("no_such_scene.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
}

TEST_F(Cli, BadCommandLinesExitWith2) {
  const std::string scene = shellQuote(kExample), out = shellQuote((dir_ / "out").string());
  const std::vector<std::string> commandLines = {
           "",                                    // no command
           "frobnicate",                                       // unknown command
           "run " + scene + " --out " + out + " --bogus",      // unknown option
           "run " + scene,                                     // no --out
           "run --out " + out,                                 // no scene
           "run " + scene + " --out " + out + " --rtol abc",   // not a number
           "run " + scene + " --out " + out + " --rtol -1",    // out of range
           "run " + scene + " --out " + out + " --t-end",      // missing value
           "run " + scene + " --out " + out + " --t-end -1",   // before t_start
  };
  for (const std::string& args : commandLines) {
    SCOPED_TRACE("flexmbd " + args);
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_FALSE(fs::exists(dir_ / "out" / "results.csv"));
  }
  const CliResult r = run("run " + scene + " --out " + out + " --bogus");
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
}

// Needs the integrator (simulate) to work.
TEST_F(Cli, ValidRunOfTheExample) {
  const fs::path out = dir_ / "out";
  const CliResult r =
      run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --t-end 0.5 --quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  ASSERT_TRUE(fs::exists(out / "results.csv"));
  std::ifstream csv(out / "results.csv");
  std::string header, line, last;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t,crank.x,crank.y,crank.theta", 0), 0u) << header;
  for (const char* col : {"slider.x_dot", "O1.fx", "O1.fy", "O1.m", "motor.effort"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col << " missing in " << header;
  }
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    last = line;
  }
  // Outputs at t = 0, 0.10472, ..., 0.41888 and exactly at t_end = 0.5.
  EXPECT_EQ(rows, 6);
  EXPECT_EQ(last.rfind("0.5,", 0), 0u) << last;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "ok");
  EXPECT_DOUBLE_EQ(summary.at("t_reached").get<double>(), 0.5);
  EXPECT_EQ(summary.at("formulation"), "ggl");
  EXPECT_GT(summary.at("steps").get<long>(), 0);
}

TEST_F(Cli, SpatialSceneRunsWithTheAugmentedLagrangianIntegrator) {
  // examples/spatial_four_bar.json (Euler parameters, three redundant equations released)
  // with "integrator": "ali3p": once refused as planar-only; it runs to the
  // end (exit 0) and conserves the energy of the undriven swing to the order-2 method's
  // global error (kSecondOrderPerRtol = 1e4 rtol, tests/test_spatial_ali3p.cpp).
  nlohmann::json j = nlohmann::json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_four_bar.json"));
  j["solver"]["integrator"] = "ali3p";
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(writeScene("spatial_ali3p.json", j).string()) + " --out " +
                          shellQuote(out.string()) + " --t-end 0.5 --quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "ok");
  EXPECT_EQ(summary.at("integrator"), "ali3p");
  EXPECT_DOUBLE_EQ(summary.at("t_reached").get<double>(), 0.5);
  EXPECT_EQ(summary.at("redundant_constraints").size(), 3u);
  const double e0 = summary.at("energy_start").get<double>(), e1 = summary.at("energy_end").get<double>();
  EXPECT_LT(std::abs(e1 - e0), 1e4 * j["solver"]["rtol"].get<double>() * std::abs(e0));
}

// Needs computeConsistentState's redundancy check (ModelError naming the driver).
TEST_F(Cli, ConflictingDriversExitWith2) {
  nlohmann::json j = example();
  j["drivers"] = nlohmann::json::parse(R"([
    {"name": "drive_a", "type": "body_angle", "body": "crank", "law": {"type": "constant_speed", "speed": 1.0}},
    {"name": "drive_b", "type": "body_angle", "body": "crank", "law": {"type": "constant_speed", "speed": 2.0}}
  ])");
  const fs::path scene = writeScene("conflict.json", j);
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) + " --quiet");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(r.err.find("drive_a") != std::string::npos || r.err.find("drive_b") != std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
}

TEST_F(Cli, RedundantJointRunsByDefaultAndRefuseExitsWith2) {
  // A second revolute joint at the crank pivot repeats O1's two equations: by default the
  // run releases them, exits 0 and names them in summary.json; with "refuse" it exits 2
  // with one error line naming the joint, and writes no results.
  nlohmann::json j = example();
  j["joints"].push_back(nlohmann::json::parse(
      R"({"name": "O1b", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], [0.0, 0.0]]})"));
  const fs::path out = dir_ / "out";
  const CliResult ok = run("run " + shellQuote(writeScene("redundant.json", j).string()) + " --out " +
                           shellQuote(out.string()) + " --quiet");
  EXPECT_EQ(ok.status, 0) << ok.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  ASSERT_EQ(summary.at("redundant_constraints").size(), 2u) << summary.dump();
  EXPECT_NE(summary.at("redundant_constraints")[0].get<std::string>().find("joint 'O1b'"), std::string::npos);
  j["solver"]["redundant_constraints"] = "refuse";
  const fs::path out2 = dir_ / "out2";
  const CliResult refused = run("run " + shellQuote(writeScene("refuse.json", j).string()) + " --out " +
                                shellQuote(out2.string()) + " --quiet");
  EXPECT_EQ(refused.status, 2);
  EXPECT_TRUE(IsOneErrorLine(refused.err)) << refused.err;
  EXPECT_NE(refused.err.find("O1b"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(out2 / "results.csv"));
}

}  // namespace

TEST_F(Cli, LockUpMidRunExitsWith1AndKeepsResultsUpToTheFailure) {
  // Rod 1.5 shorter than crank 2: the driven crank cannot pass asin(1.5/2) = 0.848 rad,
  // where the slider velocity becomes unbounded and IDA's step shrinks to min_step.
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_lockup.json") +
                          " --out " + shellQuote(out.string()));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("IDA"), std::string::npos) << r.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
  // The lock-up angle: the failure is located to IDA's minimum step, far below 1e-6.
  constexpr double kLockAngleTolerance = 1e-6;
  EXPECT_NEAR(summary.at("t_failure").get<double>(), std::asin(0.75), kLockAngleTolerance);
  EXPECT_DOUBLE_EQ(summary.at("t_reached").get<double>(), 0.8);
  // header + outputs at 0, 0.05, ..., 0.8
  const std::string csv = readFile(out / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 17);
}

TEST_F(Cli, MechanismThatCannotBeAssembledExitsWith2NamingJoints) {
  // A four-bar whose links (1 + 1 + 1) cannot span its ground pivots 10 apart.
  const nlohmann::json j = nlohmann::json::parse(R"({
    "bodies": [
      {"name": "crank",   "type": "rigid", "mass": 1, "inertia": 0.1, "angle": 1.0},
      {"name": "coupler", "type": "rigid", "mass": 1, "inertia": 0.1, "position": [0.54, 0.84], "angle": 0.3},
      {"name": "rocker",  "type": "rigid", "mass": 1, "inertia": 0.1, "position": [10, 0], "angle": 2.0}
    ],
    "joints": [
      {"name": "A", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], [0, 0]]},
      {"name": "B", "type": "revolute", "bodies": ["crank", "coupler"], "points": [[1, 0], [0, 0]]},
      {"name": "C", "type": "revolute", "bodies": ["coupler", "rocker"], "points": [[1, 0], [1, 0]]},
      {"name": "D", "type": "revolute", "bodies": ["ground", "rocker"], "points": [[10, 0], [0, 0]]}
    ],
    "drivers": [{"name": "motor", "type": "body_angle", "body": "crank", "law": {"type": "constant", "value": 1.0}}]
  })");
  const fs::path scene = writeScene("far.json", j);
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("cannot be assembled"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("residual"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("joint '"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
}

// ----- findings to fix ---------------------------------------------------------------------

namespace {

const std::string kSourceDir = FLEXMBD_SOURCE_DIR;

/// A results file as columns by name (every cell a number).
std::map<std::string, std::vector<double>> readColumns(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  {
    std::istringstream h(line);
    for (std::string n; std::getline(h, n, ',');) names.push_back(n);
  }
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(r, cell, ','); ++k) {
      if (k < names.size()) cols[names[k]].push_back(std::strtod(cell.c_str(), nullptr));
    }
  }
  return cols;
}

}  // namespace

TEST_F(Cli, SceneOfTheOtherCommandIsRefusedNamingTheCommandItIsFor) {
  struct Case {
    std::string command, scene, says;
  };
  const std::vector<Case> cases = {
      {"run", "kinematics_four_bar.json", "is a kinematics scene (key \"analysis\"): run it with \"flexmbd kinematics\""},
      {"kinematics", "slider_crank_rigid.json", "is a multibody scene (key \"bodies\"): run it with \"flexmbd run\""},
      {"kinematics", "tensegrity_two_masses.json",
       "is a tensegrity scene (key \"model\": \"tensegrity\"): run it with \"flexmbd run\""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command + " " + c.scene);
    const fs::path out = dir_ / ("out_" + c.command);
    const std::string scene = kSourceDir + "/examples/" + c.scene;
    const CliResult r = run(c.command + " " + shellQuote(scene) + " --out " + shellQuote(out.string()));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_NE(r.err.find(scene + " " + c.says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("unknown key"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "results.csv"));
    EXPECT_FALSE(fs::exists(out / "kinematics.csv"));
  }
  // A kinematics scene without "analysis" is still recognised by its links.
  nlohmann::json k = nlohmann::json::parse(readFile(kSourceDir + "/examples/kinematics_four_bar.json"));
  k.erase("analysis");
  const CliResult r = run("run " + shellQuote(writeScene("k.json", k).string()) + " --out " +
                          shellQuote((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("is a kinematics scene (key \"inputs\")"), std::string::npos) << r.err;
}

TEST_F(Cli, QuietIsAcceptedByEveryCommand) {
  const std::string four = shellQuote(kSourceDir + "/examples/kinematics_four_bar.json");
  const std::string tens = shellQuote(kSourceDir + "/examples/tensegrity_two_masses.json");
  const std::vector<std::string> commandLines = {
      "run " + shellQuote(kExample) + " --t-end 0.2 --quiet",
      "run " + shellQuote(kExample) + " --t-end 0.2 -q",
      "kinematics " + four + " --steps 6 --quiet",
      "kinematics " + four + " --steps 6 -q",
      "run " + tens + " --quiet",
      "run " + tens + " -q",
  };
  for (std::size_t k = 0; k < commandLines.size(); ++k) {
    SCOPED_TRACE("flexmbd " + commandLines[k]);
    const CliResult r = run(commandLines[k] + " --out " + shellQuote((dir_ / ("out" + std::to_string(k))).string()));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
}

TEST_F(Cli, LinkageErrorsSayLinkageOnce) {
  nlohmann::json k = nlohmann::json::parse(readFile(kSourceDir + "/examples/kinematics_four_bar.json"));
  k["inputs"] = nlohmann::json::array();  // mobility 1, no input
  const CliResult r = run("kinematics " + shellQuote(writeScene("k.json", k).string()) + " --out " +
                          shellQuote((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("linkage: mobility 1"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("linkage: linkage:"), std::string::npos) << r.err;
}

TEST_F(Cli, NumbersInMessagesArePlainDecimals) {
  nlohmann::json k = nlohmann::json::parse(readFile(kSourceDir + "/examples/kinematics_four_bar.json"));
  k["links"][0]["length"] = -80;
  CliResult r = run("kinematics " + shellQuote(writeScene("k.json", k).string()) + " --out " +
                    shellQuote((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("key \"length\" must be > 0, got -80\n"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("e+01"), std::string::npos) << r.err;

  nlohmann::json j = example();
  j["bodies"][0]["mass"] = -80;
  r = run("run " + shellQuote(writeScene("m.json", j).string()) + " --out " + shellQuote((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("key \"mass\" must be > 0, got -80\n"), std::string::npos) << r.err;
  j["bodies"][0]["mass"] = -0.001;
  r = run("run " + shellQuote(writeScene("m.json", j).string()) + " --out " + shellQuote((dir_ / "out").string()));
  EXPECT_NE(r.err.find("got -0.001\n"), std::string::npos) << r.err;
  j["bodies"][0]["mass"] = -2.5e-20;  // far from 1: exponent notation stays
  r = run("run " + shellQuote(writeScene("m.json", j).string()) + " --out " + shellQuote((dir_ / "out").string()));
  EXPECT_NE(r.err.find("got -2.5e-20\n"), std::string::npos) << r.err;
}

TEST_F(Cli, ResultsHoldAccelerationsThatMatchTheVelocities) {
  // The rigid slider-crank driven at 1 rad/s: smooth, so a central difference of a
  // velocity column over the output step h matches its acceleration column to
  // h^2/6 |v'''| (about 1e-5 here) plus the integration error.
  constexpr double kOutputStep = 0.01;
  constexpr double kFiniteDifferenceTolerance = 1e-4;  // relative to the largest |acceleration|
  nlohmann::json j = example();
  j["solver"]["output_step"] = kOutputStep;
  j["solver"]["t_end"] = 1.0;
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(writeScene("sc.json", j).string()) + " --out " +
                          shellQuote(out.string()) + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  auto cols = readColumns(out / "results.csv");
  for (const char* body : {"crank", "rod", "slider"}) {
    for (const char* c : {".x", ".y", ".theta"}) {
      const std::string name = std::string(body) + c;
      ASSERT_TRUE(cols.count(name + "_ddot")) << name << "_ddot missing";
      const std::vector<double>& v = cols[name + "_dot"];
      const std::vector<double>& a = cols[name + "_ddot"];
      ASSERT_EQ(v.size(), a.size());
      double scale = 1e-12;
      for (double x : a) scale = std::max(scale, std::fabs(x));
      for (std::size_t k = 1; k + 1 < v.size(); ++k) {
        const double dvdt = (v[k + 1] - v[k - 1]) / (2 * kOutputStep);
        EXPECT_NEAR(a[k], dvdt, kFiniteDifferenceTolerance * std::max(scale, 1.0)) << name << " at row " << k;
      }
    }
  }
  // Driven at constant speed: the crank has no angular acceleration; the slider's
  // x'' = d2/dt2 (cos t + sqrt(4 - sin^2 t)) at t = 0 is -1 - 1/2.
  for (double x : cols["crank.theta_ddot"]) EXPECT_NEAR(x, 0.0, 1e-8);
  EXPECT_NEAR(cols["slider.x_ddot"].front(), -1.5, 1e-6);
  // The order of the columns: positions, velocities, accelerations, then reactions.
  std::ifstream csv(out / "results.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_LT(header.find("slider.theta_dot,"), header.find("crank.x_ddot,")) << header;
  EXPECT_LT(header.find("slider.theta_ddot,"), header.find("O1.fx")) << header;
}

TEST_F(Cli, TensegrityResultsHoldStrutForcesInEquilibrium) {
  // A mass m hangs at rest from a strut of stiffness EA under gravity g, in its
  // equilibrium: the strut carries N = m g (tension), length l0 (1 + m g / EA).
  constexpr double m = 2.0, g = 9.81, EA = 1e4, l0 = 1.0;
  const double l = l0 * (1.0 + m * g / EA);
  constexpr double kForceTolerance = 1e-9;  // relative to m g: rounding of l - l0
  for (const char* method : {"time_stepping", "massless_cables"}) {
    SCOPED_TRACE(method);
    nlohmann::json j = {{"model", "tensegrity"}, {"dimension", 2}, {"gravity", {0.0, -g}}};
    j["nodes"] = {{{"name", "top"}, {"position", {0.0, 0.0}}, {"fixed", true}},
                  {{"name", "mass"}, {"position", {0.0, -l}}, {"mass", m}}};
    j["struts"] = {{{"name", "hanger"}, {"nodes", {"top", "mass"}}, {"EA", EA}, {"natural_length", l0}}};
    if (std::string(method) == "time_stepping") {
      j["solver"] = {{"method", method}, {"t_end", 0.05}, {"time_step", 1e-3}, {"output_step", 0.01}};
    } else {
      j["solver"] = {{"method", method}, {"t_end", 0.05}, {"output_step", 0.01}};
    }
    const fs::path out = dir_ / method;
    const CliResult r = run("run " + shellQuote(writeScene(std::string(method) + ".json", j).string()) + " --out " +
                            shellQuote(out.string()));
    ASSERT_EQ(r.status, 0) << r.err;
    auto cols = readColumns(out / "results.csv");
    ASSERT_TRUE(cols.count("hanger.force")) << "no strut force column";
    ASSERT_TRUE(cols.count("hanger.length"));
    ASSERT_GE(cols["hanger.force"].size(), 5u);
    for (double N : cols["hanger.force"]) EXPECT_NEAR(N, m * g, kForceTolerance * m * g);
    for (double L : cols["hanger.length"]) EXPECT_NEAR(L, l, 1e-12);
  }
}

TEST_F(Cli, VtkFramesOfATensegritySceneHoldItsNodesMembersAndName) {
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(kSourceDir + "/examples/tensegrity_two_masses.json") + " --out " +
                          shellQuote(out.string()) + " --vtk");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(out / "vtk" / "bodies.pvd"));
  const std::string vtu = readFile(out / "vtk" / "bodies_000000.vtu");
  EXPECT_NE(vtu.find("NumberOfPoints=\"2\" NumberOfCells=\"1\""), std::string::npos) << vtu;
  EXPECT_NE(vtu.find("Name=\"body_names\""), std::string::npos) << vtu;
  EXPECT_NE(vtu.find("Name=\"member_names\""), std::string::npos) << vtu;
  EXPECT_NE(vtu.find("<!-- member_names: c -->"), std::string::npos) << vtu;
  EXPECT_NE(vtu.find("<!-- body_names: two masses"), std::string::npos) << vtu;
  // Every row of results.csv has its frame.
  const std::string csv = readFile(out / "results.csv");
  const long rows = std::count(csv.begin(), csv.end(), '\n') - 1;
  char last[64];
  std::snprintf(last, sizeof last, "bodies_%06ld.vtu", rows - 1);
  EXPECT_TRUE(fs::exists(out / "vtk" / last)) << last;
}

TEST_F(Cli, VtkSaysOnStderrWhichBodyItCannotDraw) {
  // A flexible_invariants body without attachment points has nothing to draw.
  nlohmann::json j = nlohmann::json::parse(readFile(kSourceDir + "/examples/bari_slider_crank.json"));
  nlohmann::json loose;
  for (const auto& b : j["bodies"]) {
    if (b["type"] == "flexible_invariants") loose = b;
  }
  ASSERT_FALSE(loose.is_null());
  loose["name"] = "loose";
  loose["invariants"].erase("points");
  loose["position"] = {5.0, 5.0};
  j["bodies"].push_back(loose);
  j["solver"]["t_end"] = 0.001;
  j["solver"]["output_step"] = 0.001;
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(writeScene("loose.json", j).string()) + " --out " +
                          shellQuote(out.string()) + " --vtk --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("flexmbd: warning: --vtk: body \"loose\" has no points to draw"), std::string::npos) << r.err;
  const std::string vtu = readFile(out / "vtk" / "bodies_000000.vtu");
  EXPECT_NE(vtu.find("<!-- body_names: crank, rod, slider -->"), std::string::npos) << vtu.substr(0, 200);
}

// ----- --format hdf5 ---------------------------------------------------------------------

namespace {

/// A results table: column names and rows.
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
};

Table readCsvTable(const fs::path& path) {
  Table t;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return t;
  std::istringstream header(line);
  for (std::string field; std::getline(header, field, ',');) t.columns.push_back(field);
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) row.push_back(std::strtod(field.c_str(), nullptr));
    t.rows.push_back(row);
  }
  return t;
}

/// Reads results.h5 with the HDF5 C API, checking the documented layout on the way:
/// /columns (1-D, variable-length strings), /results (2-D float64, rows x columns,
/// extendible in rows).
Table readHdf5Table(const fs::path& path) {
  Table t;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) {
    ADD_FAILURE() << "cannot open " << path;
    return t;
  }
  const hid_t names = H5Dopen2(file, "columns", H5P_DEFAULT);
  EXPECT_GE(names, 0) << "no /columns";
  if (names >= 0) {
    const hid_t space = H5Dget_space(names);
    EXPECT_EQ(H5Sget_simple_extent_ndims(space), 1);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    std::vector<char*> text(static_cast<std::size_t>(n), nullptr);
    EXPECT_GE(H5Dread(names, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), 0);
    for (char* c : text) t.columns.emplace_back(c ? c : "");
#if H5_VERSION_GE(1, 12, 0)
    H5Treclaim(type, space, H5P_DEFAULT, text.data());
#else
    H5Dvlen_reclaim(type, space, H5P_DEFAULT, text.data());
#endif
    H5Tclose(type);
    H5Sclose(space);
    H5Dclose(names);
  }
  const hid_t results = H5Dopen2(file, "results", H5P_DEFAULT);
  EXPECT_GE(results, 0) << "no /results";
  if (results >= 0) {
    const hid_t type = H5Dget_type(results);
    EXPECT_EQ(H5Tget_class(type), H5T_FLOAT);
    EXPECT_EQ(H5Tget_size(type), 8u);
    H5Tclose(type);
    const hid_t space = H5Dget_space(results);
    hsize_t dims[2] = {0, 0}, maxDims[2] = {0, 0};
    EXPECT_EQ(H5Sget_simple_extent_ndims(space), 2);
    H5Sget_simple_extent_dims(space, dims, maxDims);
    EXPECT_EQ(maxDims[0], H5S_UNLIMITED);  // rows appended as the run goes
    EXPECT_EQ(dims[1], t.columns.size());
    std::vector<double> values(dims[0] * dims[1]);
    if (!values.empty()) {
      EXPECT_GE(H5Dread(results, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
    }
    for (hsize_t r = 0; r < dims[0]; ++r) {
      t.rows.emplace_back(values.begin() + static_cast<long>(r * dims[1]),
                          values.begin() + static_cast<long>((r + 1) * dims[1]));
    }
    H5Sclose(space);
    H5Dclose(results);
  }
  H5Fclose(file);
  return t;
}

}  // namespace

TEST_F(Cli, Hdf5ResultsHoldTheColumnsAndValuesOfTheCsv) {
  const fs::path csvOut = dir_ / "csv", h5Out = dir_ / "h5";
  const std::string args = " --t-end 0.5 --quiet";
  const CliResult rc = run("run " + shellQuote(kExample) + " --out " + shellQuote(csvOut.string()) + args);
  const CliResult rh =
      run("run " + shellQuote(kExample) + " --out " + shellQuote(h5Out.string()) + " --format hdf5" + args);
  ASSERT_EQ(rc.status, 0) << rc.err;
  ASSERT_EQ(rh.status, 0) << rh.err;
  EXPECT_TRUE(rh.err.empty()) << rh.err;
  EXPECT_NE(rh.out.find((h5Out / "results.h5").string()), std::string::npos) << rh.out;
  EXPECT_FALSE(fs::exists(h5Out / "results.csv"));
  EXPECT_EQ(nlohmann::json::parse(readFile(h5Out / "summary.json")).at("status"), "ok");
  const Table csv = readCsvTable(csvOut / "results.csv");
  const Table h5 = readHdf5Table(h5Out / "results.h5");
  EXPECT_EQ(h5.columns, csv.columns);
  ASSERT_EQ(h5.rows.size(), 6u);  // t = 0, 0.10472, ..., 0.41888 and 0.5
  ASSERT_EQ(h5.rows.size(), csv.rows.size());
  // The CSV's 17 significant digits read back exactly: the same doubles.
  for (std::size_t r = 0; r < h5.rows.size(); ++r) {
    ASSERT_EQ(h5.rows[r].size(), csv.rows[r].size()) << "row " << r;
    for (std::size_t c = 0; c < h5.rows[r].size(); ++c) {
      EXPECT_EQ(h5.rows[r][c], csv.rows[r][c]) << "row " << r << ", column " << csv.columns[c];
    }
  }
  EXPECT_EQ(h5.rows.back()[0], 0.5);
}

TEST_F(Cli, Hdf5ResultsOfAFailedRunKeepTheRowsUpToTheFailure) {
  // As LockUpMidRunExitsWith1AndKeepsResultsUpToTheFailure: outputs at 0, 0.05, ..., 0.8.
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_lockup.json") +
                          " --out " + shellQuote(out.string()) + " --format=hdf5 --quiet");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("results up to t = 0.8 kept in " + (out / "results.h5").string()), std::string::npos) << r.err;
  const Table h5 = readHdf5Table(out / "results.h5");
  ASSERT_EQ(h5.rows.size(), 17u);
  EXPECT_DOUBLE_EQ(h5.rows.back()[0], 0.8);
}

TEST_F(Cli, Hdf5ResultsOfAFullDiskAreReadableWholeRows) {
  // A file size limit of 800 KB (ulimit -f, SIGXFSZ ignored) fails the run's 630 KB of rows
  // plus the space reserved ahead of each row, as a full disk would: the writer stops
  // before HDF5 writes (which would leave an unreadable file and crash at exit).
  const fs::path out = dir_ / "out";
  const fs::path err = dir_ / "stderr.txt";
  const std::string cmd = "trap '' XFSZ; ulimit -f 800; exec " + shellQuote(FLEXMBD_CLI) + " run " +
                          shellQuote(kExample) + " --out " + shellQuote(out.string()) +
                          " --format hdf5 --quiet --t-end 200 2>" + shellQuote(err.string());
  const int rc = std::system(("bash -c " + shellQuote(cmd)).c_str());
  ASSERT_TRUE(rc != -1 && WIFEXITED(rc)) << "no normal exit: " << rc;
  EXPECT_EQ(WEXITSTATUS(rc), 1);
  const std::string message = readFile(err);
  EXPECT_TRUE(IsOneErrorLine(message));
  EXPECT_NE(message.find("cannot write '" + (out / "results.h5").string() + "' at t = "), std::string::npos)
      << message;
  EXPECT_NE(message.find("complete rows kept"), std::string::npos) << message;
  const Table h5 = readHdf5Table(out / "results.h5");
  ASSERT_GT(h5.rows.size(), 100u);
  EXPECT_LT(h5.rows.size(), 1900u);  // 1911 outputs up to t = 200
  for (std::size_t r = 1; r < h5.rows.size(); ++r) ASSERT_GT(h5.rows[r][0], h5.rows[r - 1][0]) << "row " << r;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
  // The time of the last row written (D14: was the output whose row failed).
  EXPECT_NEAR(summary.at("t_reached").get<double>(), h5.rows.back()[0], 1e-9);
}

TEST_F(Cli, UnknownFormatExitsWith2AndNoResults) {
  const fs::path out = dir_ / "out";
  const CliResult r = run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --format xlsx");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("option --format expects csv or hdf5, got 'xlsx'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
  EXPECT_FALSE(fs::exists(out / "results.h5"));
  // Only run has --format; a tensegrity scene (results.csv and events.csv) refuses hdf5.
  const CliResult k = run("kinematics " + shellQuote(kSourceDir + "/examples/kinematics_slider_crank.json") +
                          " --out " + shellQuote(out.string()) + " --format hdf5");
  EXPECT_EQ(k.status, 2);
  EXPECT_TRUE(IsOneErrorLine(k.err));
  const CliResult t = run("run " + shellQuote(kSourceDir + "/examples/tensegrity_two_masses.json") + " --out " +
                          shellQuote(out.string()) + " --format hdf5 --quiet");
  EXPECT_EQ(t.status, 2);
  EXPECT_TRUE(IsOneErrorLine(t.err));
  EXPECT_NE(t.err.find("tensegrity"), std::string::npos) << t.err;
}

// ----- flexmbd summary DIR, flexmbd plot DIR (docs/results.md) ---------------------------

TEST_F(Cli, SummaryPrintsARunReadably) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --t-end 0.5 --quiet").status,
            0);
  CliResult r = run("summary " + shellQuote(out.string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* text : {"summary of ", "status", " ok", "time reached", "0.5 s of t_end 0.5 s", "steps", "CPU time",
                           "constraint violation", "position ", "energy", "warnings", "none"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << "'" << text << "' missing in:\n" << r.out;
  }
  EXPECT_NE(r.out.find("\n"), r.out.rfind("\n")) << "one line only:\n" << r.out;
  // The summary.json file itself is accepted too.
  r = run("summary " + shellQuote((out / "summary.json").string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("time reached"), std::string::npos) << r.out;
}

TEST_F(Cli, SummaryOfAMissingOrMalformedSummaryExitsWith2) {
  CliResult r = run("summary " + shellQuote((dir_ / "nowhere").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  fs::create_directories(dir_ / "empty");  // a directory without a summary
  r = run("summary " + shellQuote((dir_ / "empty").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("summary.json"), std::string::npos) << r.err;

  fs::create_directories(dir_ / "bad");
  for (const char* text : {"{\"status\": \"ok\",\n", "[1, 2]", "{\"steps\": 3}", ""}) {
    std::ofstream(dir_ / "bad" / "summary.json") << text;
    r = run("summary " + shellQuote((dir_ / "bad").string()));
    EXPECT_EQ(r.status, 2) << text;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << text;
  }
  r = run("summary");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
}

namespace {

/// Debian's python3 with matplotlib (scripts/setup.sh installs python3-matplotlib).
bool haveMatplotlib() { return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0; }

}  // namespace

TEST_F(Cli, PlotWritesAPng) {
  if (!haveMatplotlib()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib not found (scripts/setup.sh installs it)";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --t-end 0.5 --quiet").status,
            0);
  const fs::path png = dir_ / "figures" / "slider.png";
  CliResult r = run("plot " + shellQuote(out.string()) + " --columns slider.x,slider.x_dot,O1.fx --x crank.theta --deg" +
                    " --out " + shellQuote(png.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(png.string()), std::string::npos) << r.out;
  const std::string bytes = readFile(png);
  EXPECT_GT(bytes.size(), 1000u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // Defaults: the body coordinates against t, into DIR/plot.png; two runs on one axes.
  r = run("plot " + shellQuote(out.string()) + " " + shellQuote(out.string()) + " --labels a,b");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readFile(out / "plot.png").substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

TEST_F(Cli, PlotOfAnUnknownColumnExitsWith2NamingCloseMatches) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --t-end 0.5 --quiet").status,
            0);
  CliResult r = run("plot " + shellQuote(out.string()) + " --columns slider.x,slider.xdot");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("no column 'slider.xdot'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("close matches: slider.x_dot"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "plot.png"));
  r = run("plot " + shellQuote(out.string()) + " --x time");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("'time'"), std::string::npos) << r.err;
  for (const std::string& args : std::vector<std::string>{"plot", "plot " + shellQuote((dir_ / "nowhere").string()),
                                  "plot " + shellQuote(out.string()) + " --out x.pdf",
                                  "plot " + shellQuote(out.string()) + " --frobnicate"}) {
    r = run(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << args;
  }
}

// D18: values matplotlib cannot draw (a column of 1e308, R20) and a title too long to draw
// are exit 2 naming the column or the option, never a matplotlib traceback.
TEST_F(Cli, PlotOfUndrawableValuesOrAHugeTitleExitsWith2) {
  if (!haveMatplotlib()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib not found (scripts/setup.sh installs it)";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --t-end 0.1 --quiet").status,
            0);
  CliResult r = run("plot " + shellQuote(out.string()) + " --title " + shellQuote(std::string(100000, 'T')));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("--title must be one line of at most 300 characters, got 100000"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
  // every value 1e308 (R20): the column is named
  const fs::path huge = dir_ / "huge";
  fs::create_directories(huge);
  {
    std::ofstream f(huge / "results.csv");
    f << "t,slider.x\n1e308,1e308\n1e308,1e308\n";
  }
  r = run("plot " + shellQuote(huge.string()) + " --columns slider.x");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("column 't'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("matplotlib cannot draw values beyond 1e+300"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(huge / "plot.png"));
}

// The scenes of `make demo` run and hold the columns the demo's table and plot read
// (scripts/demo_report.py, flexmbd plot): the modal one whole (0.03 s), the nodal one
// over its first 2 ms (its 3 revolutions take 2 s).
TEST_F(Cli, DemoScenesRunAndHoldTheColumnsOfTheDemo) {
  for (const std::string variant : {"modal", "nodal"}) {
    const fs::path out = dir_ / variant;
    const CliResult r = run("run " + shellQuote(kSourceDir + "/examples/slider_crank_elastic_demo_" + variant + ".json") +
                            " --out " + shellQuote(out.string()) + (variant == "nodal" ? " --t-end 0.002" : "") +
                            " --quiet");
    ASSERT_EQ(r.status, 0) << variant << ": " << r.err;
    std::ifstream csv(out / "results.csv");
    std::string header;
    std::getline(csv, header);
    for (const char* col : {"crank.theta", "slider.x", "mid.uy"}) {
      EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos) << variant << ": " << col;
    }
  }
}
