// Crashes, silent wrong results, lost data: each defect found by fuzzing and
// by trying the engine as a new user, reproduced through the command line. Every test
// here failed before its fix.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <sstream>
#include <string>

#include "cli_fixture.hpp"
#include "results/results_writer.hpp"
#include "scene/scene.hpp"
#include "linkage/kinematic_analysis.hpp"
#include "linkage/kinematics_scene.hpp"

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

// ----- deep nesting, huge values in messages ---------------------------------

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
  // the name rule refuses the name itself, before its keys are read
  EXPECT_NE(r.err.find("is 100000 characters long"), std::string::npos) << r.err.substr(0, 300);
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
  EXPECT_NE(r.err.find("key \"bodies[0]\": the name"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);
}

// ----- no `ok` with inf or NaN in the results -------------------------------

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

// Fuzz case 3654: inputs within the bound of scene numbers gave results beyond
// it with status ok (an input acceleration of 1e100 rad/s^2: 3e101 m/s^2 at the joints).
TEST(HardeningLibrary, KinematicsStopsAtResultsBeyondTheBoundOfSceneNumbers) {
  flexmbd::KinematicsScene scene = flexmbd::loadKinematicsScene(kSourceDir + "/examples/kinematics_four_bar.json");
  flexmbd::KinematicSettings settings = scene.settings;
  settings.acceleration = 1e100;
  long rows = 0;
  const flexmbd::KinematicSummary summary =
      flexmbd::analyzeKinematics(scene.linkage, settings, [&](const flexmbd::KinematicState&) { ++rows; });
  EXPECT_FALSE(summary.ok);
  EXPECT_EQ(rows, 0);
  EXPECT_NE(summary.message.find("accelerations (X'' times speed^2 plus X' times the input acceleration) beyond "
                                 "1e100 at step 0"),
            std::string::npos)
      << summary.message;
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

// ----- tolerances that cannot give a result; constraint violation warnings ------

TEST_F(Hardening, MeaninglessTolerancesAreRefused) {
  nlohmann::json j = exampleScene("slider_crank_elastic.json");
  j["solver"]["atol"] = 1e6;  // was: ok after 18 steps, deflection 31x wrong, violation 1.87 m
  CliResult r = runScene("run", writeScene("atol.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("solver.atol"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("model size"), std::string::npos) << r.err;

  j = example();
  j["solver"]["rtol"] = 0.5;
  r = runScene("run", writeScene("rtol.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("solver.rtol"), std::string::npos) << r.err;
}

TEST_F(Hardening, LargeConstraintViolationIsWarned) {
  const fs::path out = dir_ / "out";
  CliResult r = runScene("run", kExample, out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // the example at its tolerances: no warning
  EXPECT_TRUE(nlohmann::json::parse(readFile(out / "summary.json")).at("warnings").empty());

  nlohmann::json j = example();
  j["solver"]["atol"] = 1e-2;  // accepted (1/300 of the 3 m model) but coarse:
  j["solver"]["rtol"] = 1e-2;  // violations of 0.025 m and 0.03 m/s were measured
  r = runScene("run", writeScene("coarse.json", j), out);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("flexmbd: warning: position constraints violated by up to"), std::string::npos) << r.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "ok");
  EXPECT_GT(summary.at("max_position_violation").get<double>(), 1e-3 * summary.at("model_size").get<double>());
  ASSERT_FALSE(summary.at("warnings").empty());
  EXPECT_NE(summary.at("warnings")[0].get<std::string>().find("model size"), std::string::npos);
}

// ----- large moves of the consistent initialisation ----------------------------

TEST_F(Hardening, LargeInitialCorrectionIsRecordedAndWarned) {
  const fs::path out = dir_ / "out";
  nlohmann::json j = example();
  j["bodies"][0]["angle"] = 0.4;  // the crank's driver law starts at 0: moved 0.4 rad silently
  const CliResult r = runScene("run", writeScene("moved.json", j), out);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("flexmbd: warning: initial position of body 'crank' corrected: crank.theta given 0.4, now"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("driver 'motor'"), std::string::npos) << r.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  const auto& corrections = summary.at("initial_corrections");
  ASSERT_FALSE(corrections.empty());
  EXPECT_EQ(corrections[0].at("body"), "crank");
  // The driver fixes the angle at 0: the correction is the 0.4 given, to round-off.
  EXPECT_NEAR(corrections[0].at("angle").get<double>(), 0.4, 1e-12);
  EXPECT_EQ(corrections[0].at("constraint"), "driver 'motor'");
  EXPECT_EQ(summary.at("warnings").size(), 1u) << summary.at("warnings").dump();
}

TEST_F(Hardening, ElasticDisplacementBeyondSmallDeformationsIsWarned) {
  // E typed in GPa (200 instead of 2e11): the rod's elastic displacement grows far beyond
  // the small deformations of the floating frame; the run says which body and how far
  // (RMS over its mass against the model size), and hints at the units. The example as
  // shipped stays below the threshold (5 % of the model size) and says nothing of it.
  nlohmann::json j = nlohmann::json::parse(readFile(kSourceDir + "/examples/slider_crank_elastic.json"));
  j["solver"]["t_end"] = 0.05;
  const CliResult ok = runScene("run", writeScene("steel.json", j), dir_ / "steel");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(ok.err.find("elastic displacement reached"), std::string::npos) << ok.err;
  for (auto& b : j["bodies"]) {
    if (b["type"] == "flexible") b["section"]["youngs_modulus"] = 200.0;
  }
  const CliResult r = runScene("run", writeScene("gpa.json", j), dir_ / "gpa");
  const std::string said = r.err + readFile(dir_ / "gpa" / "summary.json");
  EXPECT_NE(said.find("body 'rod': its elastic displacement reached"), std::string::npos) << said;
  EXPECT_NE(said.find("E in Pa, not GPa"), std::string::npos) << said;
}

TEST_F(Hardening, InitialVelocitiesThatViolateTheJointsAreWarned) {
  // The slider given 3 m/s while the crank starts on its driver: the joints fix the
  // slider's speed, and the projection changes it; said as for positions. Bodies given at
  // rest take their joints' velocities without a warning (the example's other bodies).
  const fs::path out = dir_ / "out";
  nlohmann::json j = example();
  for (auto& b : j["bodies"]) {
    if (b["name"] == "slider") b["velocity"] = {3.0, 0.0};
  }
  const CliResult r = runScene("run", writeScene("fast.json", j), out);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("flexmbd: warning: initial velocity of body 'slider' corrected: slider.x_dot given 3, now"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("initial velocity of body 'crank'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("initial velocity of body 'rod'"), std::string::npos) << r.err;
}

// ----- output failures, signals, stale frames ---------------------------------

/// Every line of a CSV file is complete: ends in a newline, as many fields as the header.
::testing::AssertionResult WholeRows(const std::string& csv) {
  if (csv.empty() || csv.back() != '\n') return ::testing::AssertionFailure() << "does not end in a newline";
  std::istringstream in(csv);
  std::string line;
  long fields = -1, rows = 0;
  while (std::getline(in, line)) {
    const long n = std::count(line.begin(), line.end(), ',');
    if (fields < 0) fields = n;
    if (n != fields) return ::testing::AssertionFailure() << "row " << rows << " has " << n << " commas, header " << fields;
    ++rows;
  }
  return ::testing::AssertionSuccess() << rows << " lines";
}

TEST_F(Hardening, FullDiskKeepsWholeRowsAndTheSummarySaysWhy) {
  // A file size limit of 20 KB (ulimit -f, SIGXFSZ ignored) fails the writes of results.csv
  // with EFBIG in the middle of the run, as a full disk fails them with ENOSPC.
  const fs::path out = dir_ / "out";
  const CliResult r = runShell("trap '' XFSZ; ulimit -f 20; exec \"$F\" run " + shellQuote(kExample) + " --out " +
                               shellQuote(out.string()) + " --quiet");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("cannot write '" + (out / "results.csv").string() + "' at t = "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("summary.json.tmp"), std::string::npos) << r.err;
  const std::string csv = readFile(out / "results.csv");
  EXPECT_TRUE(WholeRows(csv));
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 10);  // the rows before the failure are kept
  EXPECT_FALSE(fs::exists(out / "summary.json.tmp"));
  ASSERT_TRUE(fs::exists(out / "summary.json"));
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
  EXPECT_NE(summary.at("message").get<std::string>().find("results.csv"), std::string::npos) << summary.dump();
}

TEST_F(Hardening, FullDiskInKinematicsKeepsWholeRows) {
  const fs::path out = dir_ / "out";
  const CliResult r = runShell("trap '' XFSZ; ulimit -f 8; exec \"$F\" kinematics " +
                               shellQuote(kSourceDir + "/examples/kinematics_slider_crank.json") + " --out " +
                               shellQuote(out.string()));
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("kinematics.csv' at alpha = "), std::string::npos) << r.err;
  EXPECT_TRUE(WholeRows(readFile(out / "kinematics.csv")));
  EXPECT_FALSE(fs::exists(out / "summary.json.tmp"));
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");
}

TEST_F(Hardening, SignalsEndTheRunWithAnInterruptedSummary) {
  for (const auto& [signal, status] : {std::pair<std::string, int>{"INT", 130}, {"TERM", 143}}) {
    const fs::path out = dir_ / ("out_" + signal);
    // 1e4 s of the driven crank: about 10 s of computing; the signal comes once the run
    // has written its first row (its handlers are in place: a fixed delay is not enough on
    // a slow machine or under the sanitizers, and a background job of a non-interactive
    // shell ignores SIGINT until the program installs its handler).
    const CliResult r = runShell("\"$F\" run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) +
                                 " --quiet --t-end 10000 & pid=$!; " + waitForRows(out / "results.csv", 2) +
                                 "kill -" + signal + " $pid; wait $pid");
    EXPECT_EQ(r.status, status) << signal << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_NE(r.err.find("interrupted by SIG" + signal), std::string::npos) << r.err;
    EXPECT_TRUE(WholeRows(readFile(out / "results.csv")));
    ASSERT_TRUE(fs::exists(out / "summary.json"));
    const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
    EXPECT_EQ(summary.at("status"), "interrupted");
    EXPECT_GT(summary.at("t_reached").get<double>(), 0.0);
  }
}

TEST_F(Hardening, RerunIntoAnOldOutputFolderLeavesNoFramesOfTheOldModel) {
  const fs::path out = dir_ / "out";
  CliResult r = runScene("run", kExample, out, "--vtk");  // 61 frames
  ASSERT_EQ(r.status, 0) << r.err;
  std::ofstream(out / "vtk" / "notes.txt") << "the user's own file\n";
  nlohmann::json j = example();
  j["solver"]["t_end"] = 0.5;  // 6 frames of another run
  r = runScene("run", writeScene("short.json", j), out, "--vtk");
  ASSERT_EQ(r.status, 0) << r.err;
  long frames = 0;
  for (const auto& e : fs::directory_iterator(out / "vtk")) frames += e.path().extension() == ".vtu";
  EXPECT_EQ(frames, 6);
  EXPECT_TRUE(fs::exists(out / "vtk" / "notes.txt"));
  r = runScene("run", writeScene("short.json", j), out);  // no --vtk: no frames at all
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "vtk" / "bodies_000000.vtu"));
  EXPECT_FALSE(fs::exists(out / "vtk" / "bodies.pvd"));
}

// ----- time spans the integrator cannot use are input errors, long runs run -----

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
