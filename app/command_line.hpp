/// @file
/// Command-line helpers shared by the flexmbd commands (run, kinematics, tensegrity):
/// one-line errors, option splitting and number parsing. Exit status 2 on UsageError.
#pragma once

#include <signal.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/stop_request.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd::cli {

// ----- exit status of every command (docs/command-line.md) ---------------------------
constexpr int kExitOk = 0;
/// The solver failed or a run stopped early (results up to there kept); a kinematic
/// analysis stopped at a singular position; a page, plot or eigensolver failed.
constexpr int kExitFailure = 1;
/// Bad input: command line, scene, model, folder; nothing was computed.
constexpr int kExitInputError = 2;

// ----- SIGINT / SIGTERM during a run -----------------------------------------------------
// The first signal sets a flag; the run finishes the row it is writing, writes its summary
// (status "interrupted", the time reached) and exits 128 + signal (130, 143). The handler
// resets itself: a second signal ends the process at once.

inline volatile std::sig_atomic_t gStopSignal = 0;

inline void onStopSignal(int sig) { gStopSignal = sig; }

inline void installStopHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

inline std::string signalName(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "signal " + std::to_string(sig);
}

/// Called after each output row: stops the run if a signal came.
inline void stopIfSignalled(double t) {
  if (const int sig = gStopSignal) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", t);
    throw RunInterrupted("interrupted by " + signalName(sig) + " at t = " + buf + " (the run stopped after this output)",
                         sig);
  }
}

/// The stop check of the inner loops (core/stop_request.hpp): a signal stops the run
/// within the step it is computing, the rows up to the last output kept.
inline void stopIfSignalledInStep(double t) {
  if (const int sig = gStopSignal) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", t);
    throw RunInterrupted("interrupted by " + signalName(sig) + " while computing t = " + buf, sig);
  }
}

/// While it lives: SIGINT and SIGTERM stop the calling thread's run within its step.
struct StopOnSignals {
  StopOnSignals() { installStopHandlers(); }
  StopPollScope poll{stopIfSignalledInStep};
};

/// A bad command line (exit status 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Longest message printed or written to a summary. Messages quote names and values
/// shortened (scene/json_reader.hpp); this bounds what a model error built elsewhere from a
/// huge name could still carry.
constexpr std::size_t kMaxMessageLength = 1000;

/// Messages go to the terminal on one line of at most kMaxMessageLength characters.
inline std::string oneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  if (s.size() > kMaxMessageLength) {
    std::size_t n = kMaxMessageLength - 20;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
    s = s.substr(0, n) + "... (message cut)";
  }
  return s;
}

inline void printError(const std::string& message) {
  std::cerr << "flexmbd: error: " << oneLine(message) << std::endl;
}

inline double parseNumberOption(const std::string& option, const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double x = std::strtod(begin, &end);
  if (text.empty() || end == begin || *end != '\0') {
    throw UsageError("option " + option + " expects a number, got '" + text + "'");
  }
  if (!std::isfinite(x)) throw UsageError("option " + option + " expects a finite number, got '" + text + "'");
  if (std::fabs(x) > 1e100) {  // the bound of scene numbers (scene/json_reader.hpp, kMaxInputMagnitude)
    throw UsageError("option " + option + " must be at most 1e100 in magnitude, got '" + text + "'");
  }
  return x;
}

/// What --sensitivity needs (run, modes): the message of a missing value.
inline constexpr const char* kSensitivityPathNeeded = "a scene path (e.g. --sensitivity bodies[1].mass)";

/// Takes every `--name VALUE` and `--name=VALUE` of the repeatable option `name` out of
/// `args`, values in the order given (run's and modes' --sensitivity PATH).
/// @throws UsageError "option <name> needs <what>" for a missing or empty value.
inline std::vector<std::string> takeRepeatedOption(std::vector<std::string>& args, const std::string& name,
                                                   const std::string& what) {
  std::vector<std::string> values, rest;
  const std::string prefix = name + "=";
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a == name) {
      if (k + 1 >= args.size() || args[k + 1].empty()) throw UsageError("option " + name + " needs " + what);
      values.push_back(args[++k]);
    } else if (a.rfind(prefix, 0) == 0) {
      if (a.size() == prefix.size()) throw UsageError("option " + name + " needs " + what);
      values.push_back(a.substr(prefix.size()));
    } else {
      rest.push_back(a);
    }
  }
  args = rest;
  return values;
}

inline double parsePositiveOption(const std::string& option, const std::string& text) {
  const double x = parseNumberOption(option, text);
  if (!(x > 0.0)) throw UsageError("option " + option + " must be > 0, got " + text);
  return x;
}

/// The options every command takes (run, kinematics; tensegrity scenes go through run):
/// --out DIR (required), --quiet / -q (no progress display), --help / -h.
inline const std::set<std::string> kCommonValueOptions = {"--out"};
inline const std::map<std::string, std::string> kCommonFlags = {{"--quiet", "--quiet"}, {"-q", "--quiet"}};

/// `common` plus the options of one command.
template <class C>
C withCommon(C common, const C& own) {
  common.insert(own.begin(), own.end());
  return common;
}

struct SplitArguments {
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;  ///< "--name" -> value (last one wins)
  std::set<std::string> flags;                ///< flags given
};

/// Splits arguments into positionals, `--name VALUE` / `--name=VALUE` options (names
/// in valueOptions) and flags (names in flagOptions; aliases map to their long name).
/// @throws UsageError naming the unknown option and listing the known ones.
inline SplitArguments splitArguments(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
                                     const std::map<std::string, std::string>& flagOptions,
                                     const std::string& command) {
  SplitArguments out;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a.size() < 2 || a[0] != '-') {
      out.positional.push_back(a);
      continue;
    }
    if (const auto f = flagOptions.find(a); f != flagOptions.end()) {
      out.flags.insert(f->second);
      continue;
    }
    std::string name = a, value;
    bool haveValue = false;
    if (const auto eq = a.find('='); a.rfind("--", 0) == 0 && eq != std::string::npos) {
      name = a.substr(0, eq);
      value = a.substr(eq + 1);
      haveValue = true;
    }
    if (!valueOptions.count(name)) {
      std::string known;
      for (const auto& v : valueOptions) known += (known.empty() ? "" : ", ") + v;
      for (const auto& [alias, flag] : flagOptions) {
        if (alias == flag) known += ", " + flag;
      }
      throw UsageError(command + "unknown option '" + name + "' (known options: " + known + ", --help)");
    }
    if (!haveValue) {
      if (k + 1 >= args.size()) throw UsageError("option " + name + " needs a value");
      value = args[++k];
    }
    out.values[name] = value;
  }
  return out;
}

}  // namespace flexmbd::cli
