// Shared pieces of the benchmark binaries: command-line options, timing, medians,
// least-squares fits and CSV output. Header-only; every binary includes it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace flexmbd::bench {

using Clock = std::chrono::steady_clock;

/// CPU time of this process [s] (CLOCK_PROCESS_CPUTIME_ID): for timings on a shared machine.
inline double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The whole text of a file ("" if it cannot be read: the scene reader then says so).
inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// The figures of the run with the smallest `seconds` of `repeat` calls of run() (the
/// machine is shared: the minimum is the least disturbed).
template <class Run>
auto bestOf(int repeat, Run run) {
  auto best = run();
  for (int k = 1; k < repeat; ++k) {
    const auto f = run();
    if (f.seconds < best.seconds) best = f;
  }
  return best;
}

/// Median (mean of the two middle values for an even count); NaN for an empty sample.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Median time of one call of fn over `batches` batches of n calls.
template <class F>
double timePerCall(F&& fn, int n, int batches = 7) {
  std::vector<double> t;
  for (int b = 0; b < batches; ++b) {
    const auto t0 = Clock::now();
    for (int i = 0; i < n; ++i) fn();
    t.push_back(secondsSince(t0) / n);
  }
  return median(t);
}

/// Least-squares line y = a + b x; returns {a, b}.
inline std::pair<double, double> fitLine(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return {(sy - b * sx) / n, b};
}

/// Number formatting for tables and CSV.
inline std::string fmt(double v, const char* f = "%.6g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
inline std::string sci(double v) { return fmt(v, "%.2e"); }

/// Command-line options: the common ones (--repeat, --quick, --csv, --out-dir, --help)
/// plus those a binary declares. Values are parsed into the variables given.
class Options {
 public:
  int repeat;
  bool quick = false;
  std::string csv;             ///< explicit CSV path (overrides --out-dir)
  std::string outDir = ".";    ///< directory of the CSV files

  Options(std::string program, std::string summary, int defaultRepeat)
      : repeat(defaultRepeat), program_(std::move(program)), summary_(std::move(summary)) {
    add("--repeat", "N", "timed runs per case, median reported (default " + std::to_string(defaultRepeat) + ")",
        [this](const std::string& v) { repeat = std::max(1, toInt(v, "--repeat")); });
    flag("--quick", "smoke run: a few seconds, small cases only", &quick);
    add("--csv", "FILE", "CSV output file (default: OUT_DIR/" + program_ + ".csv)",
        [this](const std::string& v) { csv = v; });
    add("--out-dir", "DIR", "directory of the CSV output (default: the working directory)",
        [this](const std::string& v) { outDir = v; });
  }

  void flag(const std::string& name, const std::string& help, bool* target) {
    specs_.push_back({name, "", help, [target](const std::string&) { *target = true; }});
  }
  void add(const std::string& name, const std::string& metavar, const std::string& help,
           std::function<void(const std::string&)> set) {
    specs_.push_back({name, metavar, help, std::move(set)});
  }
  void addInt(const std::string& name, const std::string& help, int* target) {
    add(name, "N", help, [target, name](const std::string& v) { *target = toInt(v, name); });
  }
  void addDouble(const std::string& name, const std::string& help, double* target) {
    add(name, "X", help, [target, name](const std::string& v) { *target = toDouble(v, name); });
  }
  void addString(const std::string& name, const std::string& help, std::string* target) {
    add(name, "S", help, [target](const std::string& v) { *target = v; });
  }
  /// Repeatable option collecting values (also comma-separated lists).
  void addList(const std::string& name, const std::string& help, std::vector<std::string>* target) {
    add(name, "S", help + " (repeatable, or comma-separated)", [target](const std::string& v) {
      std::stringstream ss(v);
      std::string item;
      while (std::getline(ss, item, ',')) {
        if (!item.empty()) target->push_back(item);
      }
    });
  }

  /// Parses argv. On --help prints the usage and exits 0; on an error prints it and
  /// exits 2. Unknown arguments are errors unless `passThrough` is given, which then
  /// receives them (Google Benchmark's own flags).
  void parse(int argc, char** argv, std::vector<std::string>* passThrough = nullptr) {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--help" || a == "-h") {
        usage(stdout);
        std::exit(0);
      }
      const Spec* s = nullptr;
      std::string value;
      bool inlineValue = false;
      for (const Spec& sp : specs_) {
        if (a == sp.name) s = &sp;
        if (!sp.metavar.empty() && a.rfind(sp.name + "=", 0) == 0) {
          s = &sp;
          value = a.substr(sp.name.size() + 1);
          inlineValue = true;
        }
      }
      if (!s) {
        if (passThrough) {
          passThrough->push_back(a);
          continue;
        }
        std::fprintf(stderr, "%s: unknown argument '%s'\n", program_.c_str(), a.c_str());
        usage(stderr);
        std::exit(2);
      }
      if (!s->metavar.empty() && !inlineValue) {
        if (i + 1 >= argc) {
          std::fprintf(stderr, "%s: option %s needs a value %s\n", program_.c_str(), a.c_str(), s->metavar.c_str());
          std::exit(2);
        }
        value = argv[++i];
      }
      try {
        s->set(value);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", program_.c_str(), e.what());
        std::exit(2);
      }
    }
  }

  /// Path of the CSV file `name` (e.g. "bench_scaling.csv"): --csv if given (only for
  /// the binary's main file), else OUT_DIR/name; creates the directory.
  std::string csvPath(const std::string& name, bool mainFile = true) const {
    if (mainFile && !csv.empty()) return csv;
    std::filesystem::create_directories(outDir);
    return (std::filesystem::path(outDir) / name).string();
  }

  void usage(std::FILE* f) const {
    std::fprintf(f, "usage: %s [options]\n%s\n\noptions:\n", program_.c_str(), summary_.c_str());
    for (const Spec& s : specs_) {
      const std::string lhs = s.name + (s.metavar.empty() ? "" : " " + s.metavar);
      std::fprintf(f, "  %-22s %s\n", lhs.c_str(), s.help.c_str());
    }
  }

  static int toInt(const std::string& v, const std::string& name) {
    std::size_t pos = 0;
    int r = 0;
    try {
      r = std::stoi(v, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos != v.size() || v.empty()) throw std::invalid_argument(name + ": expected an integer, got '" + v + "'");
    return r;
  }
  static double toDouble(const std::string& v, const std::string& name) {
    std::size_t pos = 0;
    double r = 0;
    try {
      r = std::stod(v, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos != v.size() || v.empty()) throw std::invalid_argument(name + ": expected a number, got '" + v + "'");
    return r;
  }

 private:
  struct Spec {
    std::string name, metavar, help;
    std::function<void(const std::string&)> set;
  };
  std::string program_, summary_;
  std::vector<Spec> specs_;
};

/// A CSV file with a fixed header; rows of already formatted fields. Lines starting
/// with '#' are comments (plot.py skips them).
class CsvWriter {
 public:
  CsvWriter(const std::string& path, const std::vector<std::string>& header) : path_(path), out_(path) {
    if (!out_) throw std::runtime_error("cannot write " + path);
    row(header);
  }
  void row(const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) out_ << (i ? "," : "") << fields[i];
    out_ << "\n";
    out_.flush();
  }
  void comment(const std::string& text) { out_ << "# " << text << "\n"; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace flexmbd::bench
