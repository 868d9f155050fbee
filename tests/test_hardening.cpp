// Issue 11 ("Crashes, silent wrong results, lost data"): each defect found by fuzzing and
// by trying the engine as a new user, reproduced through the command line. Every test
// here failed before its fix.
#include <gtest/gtest.h>

#include <csignal>
#include <string>

#include "cli_fixture.hpp"
#include "integrators/kinematic_analysis.hpp"
#include "io/kinematics_scene.hpp"
#include "io/results_writer.hpp"
#include "io/scene.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kSourceDir = FLEXMBD_SOURCE_DIR;

nlohmann::json exampleScene(const std::string& name) {
  return nlohmann::json::parse(readFile(kSourceDir + "/examples/" + name));
}

class Hardening : public Cli {
 protected:
  CliResult runScene(const std::string& command, const fs::path& scene, const fs::path& out,
                     const std::string& extra = "") const {
    return run(command + " " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) +
               (command == "run" ? " --quiet" : "") +
               (extra.empty() ? "" : " " + extra));
  }
  fs::path writeText(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

// Longest error line accepted from a scene with a 100,000-character name or value: the
// message quotes shortened values (60 characters) and is cut at 1,000 characters.
constexpr std::size_t kMaxErrorLine = 1100;

// ----- item 1: deep nesting, huge values in messages ---------------------------------

TEST_F(Hardening, DeeplyNestedJsonIsAnInputErrorForEverySubcommand) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::string deepName = "{\"name\": " + deep + "}";
  const std::string deepTensegrity = "{\"model\": \"tensegrity\", \"nodes\": " + deep + "}";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run", deep}, {"run", deepName}, {"run", deepTensegrity}, {"kinematics", deep}, {"kinematics", deepName}};
  int k = 0;
  for (const auto& [command, text] : cases) {
    const fs::path scene = writeText("deep" + std::to_string(k++) + ".json", text);
    const CliResult r = runScene(command, scene, dir_ / "out");
    EXPECT_EQ(r.status, 2) << command << " " << text.substr(0, 40) << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_NE(r.err.find("nested more than 64 levels"), std::string::npos) << r.err;
  }
}

TEST_F(Hardening, HugeNamesAndValuesAreShortenedInErrors) {
  const std::string longName(100000, 'n');
  nlohmann::json j = example();
  j["bodies"][1]["name"] = longName;
  j["bodies"][1]["masss"] = 1.0;  // an unknown key in the body with the long name
  CliResult r = runScene("run", writeScene("long_name.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("masss"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);

  j = example();
  j["name"] = nlohmann::json::array({std::string(100000, 'x'), std::string(100000, 'y')});
  r = runScene("run", writeScene("long_value.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("\"name\""), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);

  j = example();
  j["joints"][0]["bodies"][0] = longName;  // a reference to an unknown body
  r = runScene("run", writeScene("long_ref.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("unknown body"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);
}

// ----- item 2: no `ok` with inf or NaN in the results -------------------------------

TEST_F(Hardening, OverflowingInputValuesAreRefused) {
  nlohmann::json k = exampleScene("kinematics_slider_crank.json");
  k["analysis"]["speed"] = 1e308;  // accelerations speed^2 X'' overflow: all rows were NaN, status ok
  CliResult r = runScene("kinematics", writeScene("k.json", k), dir_ / "out_k");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("\"speed\""), std::string::npos) << r.err;

  nlohmann::json t = exampleScene("tensegrity_two_masses.json");
  t["nodes"][1]["mass"] = 1e308;  // energies were inf, status ok
  r = runScene("run", writeScene("t.json", t), dir_ / "out_t");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("\"mass\""), std::string::npos) << r.err;
}

TEST(HardeningLibrary, KinematicsStopsAtTheFirstNonFiniteState) {
  flexmbd::KinematicsScene scene = flexmbd::loadKinematicsScene(kSourceDir + "/examples/kinematics_slider_crank.json");
  flexmbd::KinematicSettings settings = scene.settings;
  settings.speed = 1e200;  // the API does not bound it: speed^2 = inf in the accelerations
  long rows = 0;
  const flexmbd::KinematicSummary summary =
      flexmbd::analyzeKinematics(scene.linkage, settings, [&](const flexmbd::KinematicState&) { ++rows; });
  EXPECT_FALSE(summary.ok);
  EXPECT_EQ(rows, 0);
  EXPECT_NE(summary.message.find("at step 0"), std::string::npos) << summary.message;
  EXPECT_NE(summary.message.find("non-finite accelerations"), std::string::npos) << summary.message;
}

TEST(HardeningLibrary, ResultsWriterRefusesANonFiniteRowAndKeepsTheRowsBefore) {
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_test_writer_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const flexmbd::Scene scene = flexmbd::loadScene(kSourceDir + "/examples/slider_crank_rigid.json");
  {
    flexmbd::ResultsWriter writer(dir, scene);
    flexmbd::OutputSample s;
    s.q = scene.system.initialCoordinates();
    s.v = flexmbd::VecX::Zero(s.q.size());
    s.a = s.v;
    s.lambda = flexmbd::VecX::Zero(scene.system.numConstraintEquations());
    writer.write(s);
    s.t = 0.5;
    s.v[1] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(writer.write(s), flexmbd::NonFiniteResult);
    EXPECT_EQ(writer.rowsWritten(), 1);
  }
  const std::string csv = readFile(dir / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;  // header and the row at t = 0
  EXPECT_EQ(csv.find("inf"), std::string::npos);
  fs::remove_all(dir);
}

// ----- item 7: time spans the integrator cannot use are input errors, long runs run -----

TEST_F(Hardening, UnresolvableTimeSpanIsAnInputError) {
  nlohmann::json j = example();
  j["solver"]["t_end"] = 1e-300;  // was IDA_ILL_INPUT, exit 1
  CliResult r = runScene("run", writeScene("tiny.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("solver.t_end"), std::string::npos) << r.err;

  j["solver"]["t_end"] = 2147483648.0;  // 2^31 s at the example's output step: 2e10 rows
  r = runScene("run", writeScene("rows.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("solver.output_step"), std::string::npos) << r.err;
}

TEST_F(Hardening, LongRunIsNotStoppedAtItsStartByTheDefaultMinStep) {
  nlohmann::json j = example();
  j["solver"]["t_end"] = 2147483648.0;  // 2^31 s: the default min_step was 2e-3 s, IDA failed at t = 0
  j["solver"]["output_step"] = 2147483648.0 / 10;
  j["solver"]["max_steps"] = 3000;  // the run is cut by this limit, after it got going
  const CliResult r = runScene("run", writeScene("long.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 1) << r.err;
  const auto summary = nlohmann::json::parse(readFile(dir_ / "out" / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
  // 3000 steps of the crank at 1 rad/s with rtol 1e-8 cover tens of seconds at least.
  EXPECT_GT(summary.at("t_failure").get<double>(), 10.0) << summary.dump();
  EXPECT_NE(r.err.find("IDA_TOO_MUCH_WORK"), std::string::npos) << r.err;
}

}  // namespace
