// Hardening, the input/output items: names that would break the
// result files, scene paths that are endless or special files, two runs into one output
// folder, signals in every subcommand, and the small message and status defects D12-D22 of
// ../shared/findings/reliability.md. Through the command line; exit codes and the words
// of the messages are asserted.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <string>
#include <utility>
#include <vector>

#include "cli_fixture.hpp"

namespace {

const std::string kSourceDir = FLEXMBD_SOURCE_DIR;
const fs::path kFindings = fs::path(kSourceDir) / ".." / "shared" / "findings" / "reliability-repro";

nlohmann::json exampleScene(const std::string& name) {
  return nlohmann::json::parse(readFile(kSourceDir + "/examples/" + name));
}

class IoHardening : public Cli {
 protected:
  CliResult runScene(const std::string& command, const fs::path& scene, const fs::path& out,
                     const std::string& extra = "") const {
    return run(command + " " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) +
               (extra.empty() ? "" : " " + extra));
  }
};

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << part << "\" not in: " << text;
}

// ----- D1: one rule for names, in every scene format ------------------------------------

/// Names that break a CSV header, an HDF5 column list, a VTK array name or a Python key,
/// with the words the refusal must say about them.
const std::vector<std::pair<std::string, std::string>> kHostileNames = {
    {"a,b", "has the character ',' at position 2"},
    {"rod\nx", "has the control character 0x0A at position 4"},
    {"a\"b", "has the character '\"' at position 2"},
    {"", "is empty"},
    {std::string("a\x01z"), "has the control character 0x01 at position 2"},
    {std::string(100000, 'n'), "is 100000 characters long"},
    {"arm 1", "has the character ' ' at position 4"},
    {"rod.x", "has the character '.' at position 4"},
    {"b\xC3\xA9", "has the non-ASCII byte 0xC3 at position 2"},
};

/// A scene with the name at json pointer `at` replaced by `name`.
nlohmann::json withName(nlohmann::json j, const std::string& at, const std::string& name) {
  j[nlohmann::json::json_pointer(at)] = name;
  return j;
}

struct NamedScene {
  std::string command, example, pointer, key;
};

TEST_F(IoHardening, EveryNameOfEveryFormatFollowsOneRule) {
  const std::vector<NamedScene> cases = {
      {"run", "slider_crank_rigid.json", "/bodies/1/name", "name"},
      {"run", "slider_crank_rigid.json", "/joints/2/name", "name"},
      {"run", "slider_crank_rigid.json", "/joints/2/bodies/0", "bodies[0]"},
      {"run", "slider_crank_rigid.json", "/drivers/0/name", "name"},
      {"run", "slider_crank_rigid.json", "/drivers/0/body", "body"},
      {"run", "spatial_slider_crank.json", "/bodies/0/name", "name"},
      {"run", "spatial_slider_crank.json", "/joints/0/name", "name"},
      {"run", "tensegrity_two_masses.json", "/nodes/1/name", "name"},
      {"run", "tensegrity_two_masses.json", "/cables/0/name", "name"},
      {"kinematics", "kinematics_slider_crank.json", "/nodes/1/name", "name"},
      {"kinematics", "kinematics_slider_crank.json", "/links/1/name", "name"},
      {"kinematics", "kinematics_slider_crank.json", "/inputs/0/name", "name"},
      {"modes", "slider_crank_rigid.json", "/bodies/0/name", "name"},
  };
  for (const NamedScene& c : cases) {
    for (const auto& [name, problem] : kHostileNames) {
      SCOPED_TRACE(c.example + c.pointer + " = " + name.substr(0, 20));
      const fs::path out = dir_ / "out";
      const CliResult r =
          runScene(c.command, writeScene("named.json", withName(exampleScene(c.example), c.pointer, name)), out);
      EXPECT_EQ(r.status, 2) << r.err;
      EXPECT_TRUE(IsOneErrorLine(r.err));
      EXPECT_TRUE(Contains(r.err, "key \"" + c.key + "\": the name "));
      EXPECT_TRUE(Contains(r.err, problem));
      EXPECT_TRUE(Contains(r.err, "(names are 1 to 64 characters, each an ASCII letter, a digit, '_' or '-')"));
      EXPECT_LT(r.err.size(), 400u);
      EXPECT_FALSE(fs::exists(out / "results.csv"));
      EXPECT_FALSE(fs::exists(out / "kinematics.csv"));
    }
  }
}

TEST_F(IoHardening, NamesOfTheRuleReachEveryWriterUnchanged) {
  nlohmann::json j = exampleScene("slider_crank_rigid.json");
  const std::string name = std::string("Rod_2-b") + std::string(57, 'x');  // 64 characters
  j["bodies"][1]["name"] = name;
  j["joints"][1]["bodies"][1] = name;
  j["joints"][2]["bodies"][0] = name;
  j["solver"]["t_end"] = 0.2;
  const fs::path scene = writeScene("named.json", j);
  CliResult r = runScene("run", scene, dir_ / "csv", "--quiet --vtk");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(Contains(readFile(dir_ / "csv" / "results.csv"), "," + name + ".x,"));
  EXPECT_TRUE(Contains(readFile(dir_ / "csv" / "vtk" / "bodies_000000.vtu"), name));
  r = runScene("run", scene, dir_ / "h5", "--quiet --format hdf5");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "h5" / "results.h5"));
}

// ----- D13: scene paths that are endless, special or too large --------------------------

TEST_F(IoHardening, EndlessSpecialAndHugeScenePathsAreRefused) {
  const fs::path fifo = dir_ / "scene.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path huge = dir_ / "huge.json";
  fs::resize_file(writeScene("huge.json", nlohmann::json::object()), (64ull << 20) + 1);
  struct Case {
    std::string path, words;
  };
  const std::vector<Case> cases = {
      {"/dev/zero", "it is a character device (an endless or special file such as /dev/zero)"},
      {fifo.string(), "it is a FIFO (named pipe)"},
      {huge.string(), "is 67108865 bytes, more than the limit of 67108864 bytes (64 MiB) for a scene file"},
  };
  for (const Case& c : cases) {
    for (const std::string command : {"run", "kinematics", "modes"}) {
      SCOPED_TRACE(command + " " + c.path);
      // timeout: before the fix /dev/zero and the FIFO were read without end
      const CliResult r = runShell("timeout -k 5 30 \"$F\" " + command + " " + shellQuote(c.path) + " --out " +
                                   shellQuote((dir_ / "out").string()));
      EXPECT_EQ(r.status, 2) << r.err;
      EXPECT_TRUE(IsOneErrorLine(r.err));
      EXPECT_TRUE(Contains(r.err, c.words));
      EXPECT_TRUE(Contains(r.err, c.path));
    }
  }
}

// ----- D9: two runs into one output folder ----------------------------------------------

TEST_F(IoHardening, ASecondRunIntoAFolderInUseIsRefusedAndTouchesNothing) {
  const fs::path out = dir_ / "out";
  // run A: the driven crank for 1e4 s (seconds of computing); run B starts while A runs
  const CliResult r = runShell(
      "\"$F\" run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) +
      " --quiet --t-end 10000 & a=$!; " + waitForRows(out / "results.csv", 2) + "\"$F\" run " +
      shellQuote((fs::path(kSourceDir) / "examples" / "tensegrity_two_masses.json").string()) + " --out " +
      shellQuote(out.string()) + "; echo \"B=$?\"; \"$F\" kinematics " +
      shellQuote(kSourceDir + "/examples/kinematics_slider_crank.json") + " --out " + shellQuote(out.string()) +
      "; echo \"K=$?\"; kill -INT $a; wait $a; echo \"A=$?\"");
  EXPECT_TRUE(Contains(r.out, "B=2")) << r.err;
  EXPECT_TRUE(Contains(r.out, "K=2")) << r.err;
  EXPECT_TRUE(Contains(r.out, "A=130")) << r.err;
  EXPECT_TRUE(Contains(r.err, "flexmbd: error: the output folder --out '" + out.string() +
                                  "' is being written by another run (process "));
  EXPECT_TRUE(Contains(r.err, "/.flexmbd.lock is held; wait for that run to end or give another --out"));
  // what is left is run A's alone: its columns, its summary; no events.csv of B; no lock
  const std::string header = readFile(out / "results.csv").substr(0, 40);
  EXPECT_TRUE(Contains(header, "t,crank.x,crank.y")) << header;
  EXPECT_FALSE(fs::exists(out / "events.csv"));
  EXPECT_FALSE(fs::exists(out / "kinematics.csv"));
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "interrupted");
  EXPECT_FALSE(fs::exists(out / ".flexmbd.lock"));
}

TEST_F(IoHardening, AStaleLockOfAKilledRunIsTakenOver) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  std::ofstream(out / ".flexmbd.lock") << "999999999\n";  // left by a run killed outright: not held
  nlohmann::json j = example();
  j["solver"]["t_end"] = 0.5;
  const CliResult r = runScene("run", writeScene("short.json", j), out, "--quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / ".flexmbd.lock"));
}

// ----- signals in every subcommand, not waiting for the next row -------

TEST_F(IoHardening, SigintStopsARunWithinItsStepNotAtTheNextOutput) {
  nlohmann::json j = example();
  j["solver"]["t_end"] = 1e4;
  j["solver"]["output_step"] = 1e4;  // one output, at t_end (minutes of computing)
  const fs::path out = dir_ / "out";
  const CliResult r = runShell("\"$F\" run " + shellQuote(writeScene("sparse.json", j).string()) + " --out " +
                               shellQuote(out.string()) + " --quiet & pid=$!; " +
                               waitForRows(out / "results.csv", 2) + "kill -INT $pid; "
                               "start=$(date +%s%N); wait $pid; rc=$?; "
                               "echo \"waited_ms $(( ($(date +%s%N) - start) / 1000000 ))\"; exit $rc");
  EXPECT_EQ(r.status, 130) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "interrupted by SIGINT while computing t = "));
  // before: the whole run (minutes); now one step and the summary: milliseconds, 5 s on a
  // loaded machine (whole seconds from `date +%s` made a 10 ms wait read "1" at a boundary)
  const std::size_t at = r.out.find("waited_ms ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_LT(std::stol(r.out.substr(at + 10)), 5000) << r.out;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "interrupted");
  EXPECT_EQ(summary.at("t_reached").get<double>(), 0.0);  // the row at t = 0 only
}

TEST_F(IoHardening, KinematicsHandlesSigintAndSigtermAsRunDoes) {
  nlohmann::json j = exampleScene("kinematics_slider_crank.json");
  j["analysis"]["steps"] = 10000000;  // the most allowed (kMaxKinematicSteps): ~50 s, stopped after 1 s
  for (const auto& [signal, status] : {std::pair<std::string, int>{"INT", 130}, {"TERM", 143}}) {
    const fs::path out = dir_ / ("out_" + signal);
    const CliResult r = runShell("\"$F\" kinematics " + shellQuote(writeScene("long.json", j).string()) +
                                 " --out " + shellQuote(out.string()) + " & pid=$!; " +
                                 waitForRows(out / "kinematics.csv", 2) + "kill -" + signal + " $pid; wait $pid");
    EXPECT_EQ(r.status, status) << r.err;  // before: killed by the signal
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_TRUE(Contains(r.err, "interrupted by SIG" + signal + " while computing t = "));
    const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
    EXPECT_EQ(summary.at("status"), "interrupted");  // before: "running"
    EXPECT_GT(summary.at("steps_completed").get<long>(), 0);
    EXPECT_GT(summary.at("alpha_reached").get<double>(), 0.0);
    EXPECT_FALSE(fs::exists(out / ".flexmbd.lock"));
  }
}

TEST_F(IoHardening, TensegrityRunStoppedBySigintCountsItsSteps) {
  nlohmann::json j = exampleScene("tensegrity_two_masses.json");
  j["solver"]["t_end"] = 1e5;
  j["solver"]["time_step"] = 1e-3;
  j["solver"]["output_step"] = 1.0;
  const fs::path out = dir_ / "out";
  const CliResult r = runShell("\"$F\" run " + shellQuote(writeScene("long.json", j).string()) + " --out " +
                               shellQuote(out.string()) + " --quiet & pid=$!; " +
                               waitForRows(out / "results.csv", 2) + "kill -INT $pid; wait $pid");
  EXPECT_EQ(r.status, 130) << r.err;
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "interrupted");
  EXPECT_GT(summary.at("steps").get<long>(), 0);  // D15: was 0
  EXPECT_NEAR(summary.at("steps").get<long>() * 1e-3, summary.at("t_reached").get<double>(), 1e-6);
}

TEST_F(IoHardening, ModesWithAtIsStoppedBySigterm) {
  nlohmann::json j = example();
  const CliResult r = runShell("\"$F\" modes " + shellQuote(writeScene("m.json", j).string()) + " --out " +
                               shellQuote((dir_ / "out").string()) +
                               " --at 10000 & pid=$!; sleep 1; kill -TERM $pid; wait $pid");
  EXPECT_EQ(r.status, 143) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "interrupted by SIGTERM"));
  EXPECT_TRUE(Contains(r.err, "the modes were not written"));
}

// ----- D12, D14, D16, D21: statuses and messages -----------------------------------------

TEST_F(IoHardening, VtkFolderThatIsAFileIsAnInputErrorWithASummary) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  std::ofstream(out / "vtk") << "a file\n";
  const CliResult r = runScene("run", kExample, out, "--quiet --vtk");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "--vtk: '" + (out / "vtk").string() + "' exists and is not a directory"));
  EXPECT_FALSE(Contains(r.err, "filesystem error"));
  const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary.at("status"), "failed");  // before: "running"
  EXPECT_EQ(summary.at("error"), "input");
}

TEST_F(IoHardening, FailedWriteLeavesTheTimeOfTheLastRowWritten) {
  for (const std::string format : {"csv", "hdf5"}) {
    const fs::path out = dir_ / ("out_" + format);
    // blocks of 512 bytes: the HDF5 file's own structures need more than a CSV header
    const std::string limit = format == "csv" ? "24" : "400";
    const CliResult r = runShell("trap '' XFSZ; ulimit -f " + limit + "; exec \"$F\" run " + shellQuote(kExample) +
                                 " --out " + shellQuote(out.string()) + " --quiet --t-end 1000 --format " + format);
    ASSERT_EQ(r.status, 1) << format << ": " << r.err;
    const auto summary = nlohmann::json::parse(readFile(out / "summary.json"));
    const std::string kept = "results up to t = ";
    const auto at = r.err.find(kept);
    ASSERT_NE(at, std::string::npos) << r.err;
    const double lastRow = std::stod(r.err.substr(at + kept.size()));
    EXPECT_NEAR(summary.at("t_reached").get<double>(), lastRow, 1e-5 * lastRow) << format;
    if (format == "csv") {  // the file's own last row
      const std::string csv = readFile(out / "results.csv");
      const auto lastLine = csv.rfind('\n', csv.size() - 2);
      EXPECT_DOUBLE_EQ(std::stod(csv.substr(lastLine + 1)), summary.at("t_reached").get<double>());
    }
  }
}

TEST_F(IoHardening, FullDiskAtTheStartIsExitOneWithoutAnEmptySummary) {
  const fs::path out = dir_ / "out";
  // a file size limit of 0 blocks: every write fails as on a full disk (EFBIG)
  // (stderr through a pipe: the limit would stop the message written to a file too)
  const CliResult r = runShell("( trap '' XFSZ; ulimit -f 0; exec \"$F\" run " + shellQuote(kExample) + " --out " +
                               shellQuote(out.string()) + " --quiet ) 2>&1 | cat >&2; exit ${PIPESTATUS[0]}");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "summary.json': File too large (nothing was run)"));
  EXPECT_FALSE(fs::exists(out / "summary.json"));  // before: 0 bytes
}

TEST_F(IoHardening, TensegrityTimeSpanTooShortIsAnInputError) {
  nlohmann::json j = exampleScene("tensegrity_two_masses.json");
  j["cables"][0] = {{"name", "c"}, {"nodes", {"m1", "m2"}}, {"EA", 100.0}, {"natural_length", 1.0}};
  // R19's t_end = 1e-300 is now refused by the 1e-100 floor of every positive key; the
  // time-span rule itself shows with times above the floor but a span below it
  j["solver"] = {{"method", "massless_cables"}, {"t_end", 1e-300}, {"output_step", 1e-300}};
  CliResult r = runScene("run", writeScene("tiny.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2) << r.err;  // before: exit 1, CV_ILL_INPUT
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "must be at least 1e-100")) << r.err;
  j["solver"] = {{"method", "massless_cables"}, {"t_start", 1e-90}, {"t_end", 1e-90 + 5e-101}, {"output_step", 1e-99}};
  r = runScene("run", writeScene("span.json", j), dir_ / "out2");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "solver: key \"t_end\" must give t_end - t_start >= 1e-100")) << r.err;
}

TEST_F(IoHardening, ModesIntoAReadOnlyFolderIsAnInputErrorWithTheReason) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  const fs::path out = dir_ / "ro";
  fs::create_directories(out);
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec);
  const CliResult r = runScene("modes", kExample, out);
  fs::permissions(out, fs::perms::owner_all);
  EXPECT_EQ(r.status, 2) << r.err;  // before: exit 1 "cannot write .../modes.csv"
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_TRUE(Contains(r.err, "cannot write in the output folder --out '" + out.string() + "': Permission denied"));
}

// ----- the reproducers of the findings, when ../shared is there ---------------------------

TEST_F(IoHardening, FindingsReproducersOfNames) {
  if (!fs::exists(kFindings)) GTEST_SKIP() << "no " << kFindings.string() << " (the findings of the second hardening round)";
  for (const auto& [file, command] : {std::pair<std::string, std::string>{"R01_tensegrity_name_with_comma.json", "run"},
                                      {"R02_kinematics_name_with_newline.json", "kinematics"}}) {
    const CliResult r = runScene(command, kFindings / file, dir_ / "out");
    EXPECT_EQ(r.status, 2) << file << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, "names are 1 to 64 characters"));
  }
}

}  // namespace
