// flexmbd plot DIR [DIR ...] [--columns A,B] [--x COLUMN] [--out FILE.png] [--labels L1,L2]
// [--title T] [--deg]
//
// C++ has no PNG plotting of its own here; the drawing is done by scripts/plot_results.py
// with matplotlib (Debian's python3-matplotlib, installed by scripts/setup.sh for
// /usr/bin/python3). This command checks what it can first — the directories, their
// results file and every column name (exit 2 with one line naming close matches) — and
// then runs the script, so the errors of the command line look like those of run and
// kinematics, and a plot needs no Python knowledge.
//
// The script is looked for in: $FLEXMBD_PLOT_SCRIPT; <bin>/../share/flexmbd/ (installed
// by `cmake --install`); the scripts/ folder of the source tree the binary was built
// from. The interpreter: $FLEXMBD_PYTHON, else /usr/bin/python3, else python3 on PATH
// (the script runs itself again with /usr/bin/python3 if its interpreter lacks matplotlib).
#include "app/plot_command.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "app/command_line.hpp"

#ifndef FLEXMBD_SCRIPTS_DIR
#define FLEXMBD_SCRIPTS_DIR ""
#endif

namespace flexmbd {

namespace {

namespace fs = std::filesystem;

using cli::kExitOk;
using cli::kExitFailure;
using cli::kExitInputError;

const char* const kScriptName = "plot_results.py";

/// The header row of a CSV file (RFC 4180 quoting, as results/results_writer.cpp writes it).
std::vector<std::string> readHeader(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cli::UsageError("plot: cannot open " + path.string());
  std::vector<std::string> fields(1);
  bool quoted = false;
  char c;
  while (in.get(c)) {
    if (quoted) {
      if (c == '"') {
        if (in.peek() == '"') {
          in.get(c);
          fields.back() += '"';
        } else {
          quoted = false;
        }
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c == '\n') {
      break;
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  if (fields.size() == 1 && fields[0].empty()) throw cli::UsageError("plot: " + path.string() + " is empty (no header)");
  return fields;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// Up to five columns close to `name`: few edits away, or containing it.
std::vector<std::string> closeMatches(const std::string& name, const std::vector<std::string>& header) {
  std::vector<std::pair<std::size_t, std::string>> scored;
  const std::size_t limit = std::max<std::size_t>(1, name.size() / 4);
  for (const std::string& h : header) {
    const std::size_t d = editDistance(name, h);
    if (d <= limit) {
      scored.emplace_back(d, h);
    } else if (!name.empty() && h.size() > 1 && (h.find(name) != std::string::npos || name.find(h) != std::string::npos)) {
      scored.emplace_back(limit + 1, h);
    }
  }
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (std::size_t k = 0; k < scored.size() && k < 5; ++k) out.push_back(scored[k].second);
  return out;
}

std::string joined(const std::vector<std::string>& v, std::size_t max) {
  std::string s;
  for (std::size_t k = 0; k < v.size() && k < max; ++k) s += (k ? ", " : "") + v[k];
  if (v.size() > max) s += ", ...";
  return s;
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s + ",") {
    if (c == ',') {
      const auto b = cur.find_first_not_of(" \t"), e = cur.find_last_not_of(" \t");
      if (b != std::string::npos) out.push_back(cur.substr(b, e - b + 1));
      cur.clear();
    } else {
      cur += c;
    }
  }
  return out;
}

bool isExecutable(const fs::path& p) { return ::access(p.c_str(), X_OK) == 0 && fs::is_regular_file(p); }

fs::path findScript(const std::string& name = kScriptName) {
  if (const char* env = std::getenv("FLEXMBD_PLOT_SCRIPT"); env && *env && name == kScriptName) return env;
  std::vector<fs::path> candidates;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(self.parent_path().parent_path() / "share" / "flexmbd" / name);
  if (*FLEXMBD_SCRIPTS_DIR) candidates.push_back(fs::path(FLEXMBD_SCRIPTS_DIR) / name);
  std::string looked;
  for (const fs::path& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c;
    looked += (looked.empty() ? "" : ", ") + c.string();
  }
  throw std::runtime_error("plot: cannot find " + name + " (looked in " + looked +
                           (name == kScriptName ? "; set FLEXMBD_PLOT_SCRIPT to its path)" : ")"));
}

std::string findPython() {
  if (const char* env = std::getenv("FLEXMBD_PYTHON"); env && *env) return env;
  if (isExecutable("/usr/bin/python3")) return "/usr/bin/python3";
  return "python3";  // on PATH
}

/// Runs argv[0] (looked up on PATH if it has no slash) and waits: its exit status, or 1.
int runAndWait(const std::vector<std::string>& argv) {
  std::vector<char*> cargv;
  for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  // SIGINT and SIGTERM stop the script as they stop a run: flexmbd takes them and ends the
  // script (SIGTERM), which ignores the terminal's SIGINT (no KeyboardInterrupt traceback).
  cli::installStopHandlers();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("plot: cannot start ") + argv[0] + ": " + std::strerror(errno));
  if (pid == 0) {
    ::signal(SIGINT, SIG_IGN);
    ::signal(SIGTERM, SIG_DFL);
    ::execvp(cargv[0], cargv.data());
    const std::string msg = "flexmbd: error: plot: cannot run " + argv[0] + ": " + std::strerror(errno) +
                            " (the plots need Python 3 with matplotlib: scripts/setup.sh installs Debian's "
                            "python3-matplotlib)\n";
    (void)!::write(2, msg.data(), msg.size());
    ::_exit(127);
  }
  int status = 0;
  bool forwarded = false;
  for (;;) {
    if (cli::gStopSignal && !forwarded) {  // also one that came before the wait began
      ::kill(pid, SIGTERM);
      forwarded = true;
    }
    if (::waitpid(pid, &status, 0) >= 0) break;
    if (errno != EINTR) throw std::runtime_error(std::string("plot: waiting for the plot script: ") + std::strerror(errno));
  }
  if (const int sig = cli::gStopSignal) {
    cli::printError("plot: interrupted by " + cli::signalName(sig) + " (the plot script was stopped; no plot written)");
    return 128 + sig;
  }
  if (!WIFEXITED(status)) return kExitFailure;
  const int rc = WEXITSTATUS(status);
  return rc == kExitOk || rc == kExitInputError ? rc : kExitFailure;
}

}  // namespace

int runPythonScript(const std::string& scriptName, const std::vector<std::string>& args) {
  std::vector<std::string> argv = {findPython(), findScript(scriptName).string()};
  argv.insert(argv.end(), args.begin(), args.end());
  return runAndWait(argv);
}

int runPlotCommand(const std::vector<std::string>& args) {
  std::vector<std::string> scriptArgs;
  try {
    const cli::SplitArguments split = cli::splitArguments(
        args, cli::withCommon(cli::kCommonValueOptions, {"--columns", "--x", "--labels", "--title"}),
        cli::withCommon(cli::kCommonFlags, {{"--deg", "--deg"}}), "plot: ");
    const std::vector<std::string>& dirs = split.positional;
    if (dirs.empty()) throw cli::UsageError("plot: missing the output directory (flexmbd plot DIR [--columns A,B])");
    const auto value = [&](const std::string& name) -> const std::string* {
      const auto it = split.values.find(name);
      return it == split.values.end() ? nullptr : &it->second;
    };
    std::vector<std::string> columns;
    if (const std::string* c = value("--columns")) {
      columns = splitList(*c);
      if (columns.empty()) throw cli::UsageError("option --columns needs column names (--columns a,b)");
    }
    if (const std::string* l = value("--labels"); l && splitList(*l).size() != dirs.size()) {
      throw cli::UsageError("plot: --labels gives " + std::to_string(splitList(*l).size()) + " labels for " +
                            std::to_string(dirs.size()) + " directories");
    }
    if (const std::string* o = value("--out")) {
      if (o->size() < 5 || o->compare(o->size() - 4, 4, ".png") != 0) {
        throw cli::UsageError("plot: --out '" + *o + "' must name a .png file");
      }
    }
    bool kinematics = false;
    for (std::size_t k = 0; k < dirs.size(); ++k) {
      const fs::path dir(dirs[k]);
      std::error_code ec;
      if (!fs::is_directory(dir, ec)) {
        throw cli::UsageError("plot: '" + dirs[k] + "' is not a directory (give the --out DIR of flexmbd run or kinematics)");
      }
      fs::path file = dir / "results.csv";
      bool isKinematics = false;
      if (!fs::is_regular_file(file, ec)) {
        file = dir / "kinematics.csv";
        isKinematics = true;
        if (!fs::is_regular_file(file, ec)) throw cli::UsageError("plot: " + dirs[k] + " holds neither results.csv nor kinematics.csv");
      }
      if (k == 0) kinematics = isKinematics;
      if (isKinematics != kinematics) throw cli::UsageError("plot: cannot draw results.csv and kinematics.csv on the same axes");
      const std::vector<std::string> header = readHeader(file);
      std::vector<std::string> wanted = columns;
      const std::string* x = value("--x");
      wanted.insert(wanted.begin(), x ? *x : kinematics ? "alpha" : "t");
      for (const std::string& name : wanted) {
        if (std::find(header.begin(), header.end(), name) != header.end()) continue;
        const std::vector<std::string> near = closeMatches(name, header);
        throw cli::UsageError("plot: " + file.string() + " has no column '" + name + "' (" +
                              (near.empty() ? "it has " + std::to_string(header.size()) + " columns: " + joined(header, 8)
                                            : "close matches: " + joined(near, 5)) +
                              ")");
      }
    }
    for (const auto& [name, v] : split.values) {
      scriptArgs.push_back(name);
      scriptArgs.push_back(v);
    }
    if (split.flags.count("--deg")) scriptArgs.push_back("--deg");
    scriptArgs.push_back("--");  // the directories, even one named like an option
    scriptArgs.insert(scriptArgs.end(), dirs.begin(), dirs.end());
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
  try {
    std::vector<std::string> argv = {findPython(), findScript().string()};
    ::setenv("FLEXMBD_PLOT_FROM_CLI", "1", 1);  // the script's errors then read "flexmbd: error: plot: ..."
    argv.insert(argv.end(), scriptArgs.begin(), scriptArgs.end());
    return runAndWait(argv);
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitFailure;
  }
}

}  // namespace flexmbd
