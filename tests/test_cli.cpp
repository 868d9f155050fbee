// Unit tests of the command line (app/flexmbd_main.cpp): exit status, the one-line
// error on stderr, and the files left in the output directory. The binary is run
// through the shell (std::system) in a fresh temporary directory per test.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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
