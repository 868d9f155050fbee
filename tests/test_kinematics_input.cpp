// Bad input to the kinematic analysis (scene files and the C++ API): one clear line per
// error, naming the object and what was expected; and the command line's exit statuses.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "linkage/kinematics_scene.hpp"

using namespace flexmbd;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json sliderCrank() {
  return json::parse(R"({
    "name": "slider-crank",
    "nodes": [
      {"name": "O1", "type": "fixed",  "position": [0, 0]},
      {"name": "O2", "type": "free",   "position": [1, 0]},
      {"name": "O3", "type": "slider", "position": [3, 0], "direction": [1, 0]}
    ],
    "links": [
      {"name": "crank", "nodes": ["O1", "O2"]},
      {"name": "rod",   "nodes": ["O2", "O3"]}
    ],
    "inputs": [{"name": "alpha", "type": "link_angle", "link": "crank", "node": "O1"}],
    "analysis": {"steps": 12}
  })");
}

/// The message of the InputError thrown by parsing `j` ("" if none).
std::string errorOf(const json& j) {
  try {
    parseKinematicsSceneText(j.dump(), "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectError(const json& j, const std::string& part) {
  const std::string m = errorOf(j);
  EXPECT_NE(m.find(part), std::string::npos) << "message: '" << m << "' should contain '" << part << "'";
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_EQ(m.rfind("scene.json: ", 0), 0u) << m;
}

}  // namespace

TEST(KinematicsInput, ValidSceneParses) {
  EXPECT_EQ(errorOf(sliderCrank()), "");
  const KinematicsScene s = parseKinematicsSceneText(sliderCrank().dump());
  EXPECT_EQ(s.linkage.mobility(), 1);
  EXPECT_EQ(s.settings.steps, 12);
}

TEST(KinematicsInput, DisconnectedLink) {
  json j = sliderCrank();
  j["nodes"].push_back({{"name", "P"}, {"type", "free"}, {"position", {5, 5}}});
  j["nodes"].push_back({{"name", "Q"}, {"type", "free"}, {"position", {6, 5}}});
  j["links"].push_back({{"name", "loose"}, {"nodes", {"P", "Q"}}});
  expectError(j, "link 'loose' is disconnected: no chain of links joins it to a fixed or slider node");
}

TEST(KinematicsInput, NodeOnNoLink) {
  json j = sliderCrank();
  j["nodes"].push_back({{"name", "P"}, {"type", "free"}, {"position", {5, 5}}});
  expectError(j, "node 'P' is not connected to any link");
}

TEST(KinematicsInput, NodeNamedTwice) {
  json j = sliderCrank();
  j["nodes"][2]["name"] = "O2";
  expectError(j, "nodes[2] (\"O2\"): node 'O2' is defined twice");
}

TEST(KinematicsInput, LinkNamedTwice) {
  json j = sliderCrank();
  j["links"][1]["name"] = "crank";
  expectError(j, "link 'crank' is defined twice");
}

TEST(KinematicsInput, WrongNumberOfInputsReportsTheMobility) {
  json j = sliderCrank();
  j["inputs"].push_back({{"name", "piston"}, {"type", "slider_position"}, {"node", "O3"}});
  expectError(j, "mobility 1 (7 coordinates - 3 x 2 links) needs 1 input, got 2");
  j = sliderCrank();
  j["inputs"] = json::array();
  expectError(j, "mobility 1 (7 coordinates - 3 x 2 links) needs 1 input, got 0");
  // A five-bar has mobility 2.
  j = sliderCrank();
  j["nodes"][2] = {{"name", "O3"}, {"type", "free"}, {"position", {2, 1}}};
  j["nodes"].push_back({{"name", "O4"}, {"type", "free"}, {"position", {3, 0.5}}});
  j["nodes"].push_back({{"name", "O5"}, {"type", "fixed"}, {"position", {3, 0}}});
  j["links"].push_back({{"name", "l3"}, {"nodes", {"O3", "O4"}}});
  j["links"].push_back({{"name", "l4"}, {"nodes", {"O5", "O4"}}});
  expectError(j, "mobility 2 (14 coordinates - 3 x 4 links) needs 2 inputs, got 1");
}

TEST(KinematicsInput, StructureHasNothingToDrive) {
  json j = sliderCrank();
  j["nodes"][2]["type"] = "fixed";
  j["nodes"][2].erase("direction");
  expectError(j, "mobility 0");
}

TEST(KinematicsInput, ZeroLengthLinks) {
  json j = sliderCrank();
  j["nodes"][1]["position"] = {0, 0};
  expectError(j, "link 'crank': zero length (nodes 'O1' and 'O2' are at the same position");
  j = sliderCrank();
  j["links"][0]["length"] = 0;
  expectError(j, "links[0] (\"crank\"): key \"length\" must be > 0, got 0");
  j = sliderCrank();
  j["links"][0]["nodes"] = {"O1", "O1"};
  expectError(j, "both ends are node 'O1'");
}

TEST(KinematicsInput, NonFiniteNumbers) {
  // JSON has no NaN or Infinity; a literal too large for a double is the way in.
  std::string text = sliderCrank().dump();
  text.replace(text.find("[1,0]"), 5, "[1e999,0]");
  try {
    parseKinematicsSceneText(text, "scene.json");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too large for a double"), std::string::npos) << e.what();
  }
  // Through the C++ API.
  Linkage2d l;
  EXPECT_THROW(l.addFreeNode("A", {std::nan(""), 0}), InputError);
  l.addFixedNode("B", {0, 0});
  l.addFreeNode("C", {1, 0});
  EXPECT_THROW(l.addLink("bc", "B", "C", HUGE_VAL), InputError);
  try {
    l.addFreeNode("D", {0, INFINITY});
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "node 'D': position must be finite numbers, got [0, inf]");
  }
  KinematicSettings st;
  st.speed = NAN;
  EXPECT_THROW(st.validate(), InputError);
}

TEST(KinematicsInput, StrictKeysAndTypes) {
  json j = sliderCrank();
  j["nodes"][0]["mass"] = 1;
  expectError(j, "nodes[0] (\"O1\"): unknown key \"mass\" (allowed keys for a fixed node: name, type, position)");
  j = sliderCrank();
  j["analysis"]["step"] = 10;
  expectError(j, "analysis: unknown key \"step\"");
  j = sliderCrank();
  j["links"][1]["nodes"] = {"O2", "O9"};
  expectError(j, "unknown node 'O9' (known nodes: O1, O2, O3)");
  j = sliderCrank();
  j["inputs"][0]["link"] = "rod";
  expectError(j, "node 'O1' is not an end of link 'rod'");
  j = sliderCrank();
  j["analysis"]["corrector"] = "secant";
  expectError(j, "key \"corrector\" must be \"newton\" or \"modified_newton\"");
  j = sliderCrank();
  j["analysis"]["steps"] = 0;
  expectError(j, "key \"steps\" must be >= 1, got 0");
  j = sliderCrank();
  j["nodes"][2]["direction"] = {0, 0};
  expectError(j, "the slider direction must be a finite non-zero vector, got [0, 0]");
  EXPECT_NE(errorOf(json::parse("[1, 2]")).find("expected an object"), std::string::npos);
  try {
    parseKinematicsSceneText(R"({"name": "a", "name": "b"})", "scene.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("duplicate key \"name\""), std::string::npos) << e.what();
  }
}

TEST(KinematicsInput, CannotBeAssembled) {
  json j = sliderCrank();
  j["links"][1]["length"] = 0.5;  // rod shorter than the crank's reach to the slider line: 1 + 0.5 < 3
  j["nodes"][2]["position"] = {3, 1};  // O3's line y = 1... the rod cannot reach it
  try {
    const KinematicsScene s = parseKinematicsSceneText(j.dump(), "scene.json");
    KinematicAnalysis a(s.linkage, s.settings);
    FAIL() << "expected a ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be assembled"), std::string::npos) << e.what();
  }
}

// ----- the command line -------------------------------------------------------------

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

struct CliResult {
  int status = -1;
  std::string out, err;
};

class KinematicsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("flexmbd_test_kin_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  CliResult run(const std::string& args) const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = "'" + std::string(FLEXMBD_CLI) + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int rc = std::system(cmd.c_str());
    CliResult r;
    r.status = (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
  }
  std::string example(const std::string& name) const { return std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + name; }
  fs::path dir_;
};

int countLines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace

TEST_F(KinematicsCli, SliderCrankExitsZeroAndWritesOneRowPerStep) {
  const CliResult r = run("kinematics '" + example("kinematics_slider_crank.json") + "' --out '" + (dir_ / "out").string() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("flexmbd: ok"), std::string::npos);
  const std::string csv = readFile(dir_ / "out" / "kinematics.csv");
  EXPECT_EQ(countLines(csv), 62);  // header + steps 0..60
  EXPECT_EQ(csv.rfind("step,alpha,iterations,residual,rcond,crank_angle,O1.x,", 0), 0u) << csv.substr(0, 80);
  EXPECT_NE(csv.find("O3.d2x_da2"), std::string::npos);
  EXPECT_NE(csv.find("rod.omega_dot"), std::string::npos);
  const json s = json::parse(readFile(dir_ / "out" / "summary.json"));
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["steps_completed"], 60);
  EXPECT_LE(s["max_residual"].get<double>(), 1e-13);
  EXPECT_TRUE(s["singular"].is_null());
}

TEST_F(KinematicsCli, LockExitsOneAndKeepsTheStepsBeforeIt) {
  const CliResult r = run("kinematics '" + example("kinematics_four_bar_lock.json") + "' --out '" + (dir_ / "out").string() + "'");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("locks at input alpha = 2.36029"), std::string::npos) << r.err;
  EXPECT_EQ(countLines(readFile(dir_ / "out" / "kinematics.csv")), 24);  // header + steps 0..22
  const json s = json::parse(readFile(dir_ / "out" / "summary.json"));
  EXPECT_EQ(s["status"], "failed");
  EXPECT_EQ(s["singular"]["kind"], "lock");
  EXPECT_NEAR(s["singular"]["alpha"].get<double>(), std::acos(-0.71), 1e-9);
}

TEST_F(KinematicsCli, BadSceneExitsTwoWithOneLineAndNoResults) {
  json j = sliderCrank();
  j["inputs"] = json::array();
  const fs::path scene = dir_ / "bad.json";
  std::ofstream(scene) << j.dump();
  const CliResult r = run("kinematics '" + scene.string() + "' --out '" + (dir_ / "out").string() + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("flexmbd: error: "), std::string::npos);
  EXPECT_NE(r.err.find("mobility 1"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "kinematics.csv"));
  EXPECT_EQ(json::parse(readFile(dir_ / "out" / "summary.json"))["error"], "input");
}

TEST_F(KinematicsCli, BadCommandLinesExitTwo) {
  EXPECT_EQ(run("kinematics").status, 2);
  EXPECT_EQ(run("kinematics '" + example("kinematics_slider_crank.json") + "'").status, 2);  // no --out
  EXPECT_EQ(run("kinematics '" + example("kinematics_slider_crank.json") + "' --out x --steps 0").status, 2);
  EXPECT_EQ(run("kinematics '" + example("kinematics_slider_crank.json") + "' --out x --bogus 1").status, 2);
  EXPECT_EQ(run("kinematics '" + (dir_ / "missing.json").string() + "' --out '" + (dir_ / "o").string() + "'").status, 2);
  const CliResult help = run("kinematics --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("flexmbd kinematics SCENE.json --out DIR"), std::string::npos);
}

TEST_F(KinematicsCli, OptionsOverrideTheScene) {
  const CliResult r = run("kinematics '" + example("kinematics_four_bar.json") + "' --out '" + (dir_ / "out").string() +
                          "' --steps 12 --corrector=modified_newton --tolerance 1e-12");
  EXPECT_EQ(r.status, 0) << r.err;
  const json s = json::parse(readFile(dir_ / "out" / "summary.json"));
  EXPECT_EQ(s["steps"], 12);
  EXPECT_EQ(s["corrector"], "modified_newton");
  EXPECT_EQ(s["tolerance"], 1e-12);
}
