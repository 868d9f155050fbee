// The fixture of the command-line tests (tests/test_cli.cpp, tests/test_hardening.cpp):
// runs the flexmbd binary through the shell in a fresh temporary directory per test and
// captures its exit status, stdout and stderr.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

const std::string kExample = std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json";

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

struct CliResult {
  int status = -1;  ///< exit status, -1 if the process did not exit normally
  std::string out, err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("flexmbd_test_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);  // kept for inspection on failure
  }

  /// Runs `flexmbd <args>` (args already shell-quoted where needed).
  CliResult run(const std::string& args) const {
    const fs::path out = dir_ / "cli_stdout.txt", err = dir_ / "cli_stderr.txt";
    const std::string cmd = shellQuote(FLEXMBD_CLI) + " " + args + " >" + shellQuote(out.string()) + " 2>" +
                            shellQuote(err.string());
    const int rc = std::system(cmd.c_str());
    CliResult r;
    r.status = (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
  }

  /// Runs `shell` (a command line where $F is the flexmbd binary) through bash -c.
  CliResult runShell(const std::string& shell) const {
    const fs::path out = dir_ / "cli_stdout.txt", err = dir_ / "cli_stderr.txt";
    const std::string cmd = "F=" + shellQuote(FLEXMBD_CLI) + "; { " + shell + "; } >" + shellQuote(out.string()) +
                            " 2>" + shellQuote(err.string());
    const int rc = std::system(("bash -c " + shellQuote(cmd)).c_str());
    CliResult r;
    r.status = (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
  }

  fs::path writeScene(const std::string& name, const nlohmann::json& j) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << j.dump(2);
    return p;
  }

  static nlohmann::json example() { return nlohmann::json::parse(readFile(kExample)); }

  fs::path dir_;
};

/// A shell snippet (ending in "; ") that waits until the text file `path` has at least
/// `rows` lines, at most 60 s: a run has then installed its signal handlers and written its
/// first rows. Signal tests send their signal after it, not after a fixed delay (too short
/// on a loaded machine or under the sanitizers: a background job of a non-interactive
/// shell ignores SIGINT until the program installs its handler).
inline std::string waitForRows(const fs::path& path, int rows) {
  return "for i in $(seq 600); do [ \"$(wc -l 2>/dev/null < " + shellQuote(path.string()) + " || echo 0)\" -ge " +
         std::to_string(rows) + " ] && break; sleep 0.1; done; ";
}

/// One line starting with "flexmbd: error:".
::testing::AssertionResult IsOneErrorLine(const std::string& err) {
  if (err.rfind("flexmbd: error:", 0) != 0) return ::testing::AssertionFailure() << "stderr: " << err;
  const auto nl = err.find('\n');
  if (nl == std::string::npos || nl + 1 != err.size()) {
    return ::testing::AssertionFailure() << "stderr is not exactly one line: " << err;
  }
  return ::testing::AssertionSuccess();
}


}  // namespace
