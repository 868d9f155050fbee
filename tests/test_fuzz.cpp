// Fuzz test of the command line (issue 11, "Kept fixed"): a seeded generator damages the
// example scenes of every subcommand (run: multibody rigid and elastic, tensegrity;
// kinematics) — deleted keys, wrong types, huge, tiny and non-finite numbers, deep
// nesting, truncated and binary files, long names — and runs the binary on each. Every
// run must end within a time limit with exit status 0, 1 or 2, never exit 0 with inf or
// NaN in its results, and an exit-2 message must be one line naming what was wrong.
// Reproduce a case: FLEXMBD_FUZZ_KEEP=1 keeps the scenes of failed cases in /tmp.
// Explore further: FLEXMBD_FUZZ_SEED=n and FLEXMBD_FUZZ_CASES=n change the seed and count.
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>
#include <vector>

#include "cli_fixture.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Number of damaged scenes and the seed of the generator. 400 cases take about 15 s in
// Release (most are input errors, found in milliseconds).
constexpr int kCases = 400;
constexpr unsigned kSeed = 20261123;
// Time limit of one case. The longest valid case (the elastic slider-crank over its
// 0.042 s) takes 0.4 s in Release; 30 s leaves room for a sanitizer build.
constexpr int kTimeLimitSeconds = 30;

struct Base {
  std::string command;  // "run" or "kinematics"
  std::string file;     // examples/<file>
};

const std::vector<Base> kBases = {{"run", "slider_crank_rigid.json"},
                                  {"run", "slider_crank_elastic.json"},
                                  {"run", "tensegrity_two_masses.json"},
                                  {"kinematics", "kinematics_slider_crank.json"},
                                  {"kinematics", "kinematics_four_bar.json"}};

/// Every value of a JSON tree, as JSON pointers.
void collectPointers(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) collectPointers(*it, at / it.key(), out);
  } else if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) collectPointers(j[k], at / k, out);
  }
}

class Generator {
 public:
  explicit Generator(unsigned seed) : rng_(seed) {}
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

  json number() {
    static const std::vector<double> values = {1e308, -1e308, 1e100, -1e100, 1e99, 1e-308, 5e-324, -5e-324,
                                               0.0,   -0.0,   -1.0,  1e-300, 2147483648.0, 9.3e18, 1e15, 0.5,
                                               3.0,   1e-15,  -1e-3, 123456789.0};
    return values[pick(static_cast<int>(values.size()))];
  }
  json wrongType(const json& v) {
    switch (pick(7)) {
      case 0: return "1.0";
      case 1: return json::array({1, 2, 3});
      case 2: return json::object({{"x", 1}});
      case 3: return true;
      case 4: return nullptr;
      case 5: return v.is_string() ? json(42) : json("");
      default: return json::array();
    }
  }
  json deep() {
    json v = json::array();
    const int depth = 1 + pick(100);
    for (int k = 0; k < depth; ++k) v = json::array({v});
    return v;
  }

  /// The text of one damaged scene.
  std::string damage(const json& base) {
    const int kind = pick(10);
    const std::string text = base.dump(1);
    if (kind == 0) {  // truncated file
      return text.substr(0, pick(static_cast<int>(text.size())));
    }
    if (kind == 1) {  // binary garbage, alone or spliced into the file
      std::string bytes(1 + pick(400), '\0');
      for (char& c : bytes) c = static_cast<char>(pick(256));
      if (pick(2)) return bytes;
      const std::size_t at = pick(static_cast<int>(text.size()));
      return text.substr(0, at) + bytes + text.substr(at);
    }
    if (kind == 2) {  // nesting far beyond any limit, as text
      const int depth = pick(2) ? 100000 : 70;
      const std::string d = std::string(depth, '[') + std::string(depth, ']');
      return pick(2) ? d : "{\"name\": " + d + "}";
    }
    json j = base;
    const int edits = 1 + pick(3);
    for (int e = 0; e < edits; ++e) {
      std::vector<json::json_pointer> ptrs;
      collectPointers(j, json::json_pointer(), ptrs);
      const json::json_pointer p = ptrs[pick(static_cast<int>(ptrs.size()))];
      if (p.empty()) continue;
      json& v = j[p];
      switch (kind) {
        case 3:  // delete the key or element
          j[p.parent_pointer()].is_object() ? (void)j[p.parent_pointer()].erase(p.back())
                                            : (void)j[p.parent_pointer()].erase(std::stoul(p.back()));
          break;
        case 4: v = wrongType(v); break;
        case 5:
        case 6: {  // numbers: replace one, preferably a number
          for (int tries = 0; tries < 20 && !j[p].is_number(); ++tries) {
            const json::json_pointer q = ptrs[pick(static_cast<int>(ptrs.size()))];
            if (!q.empty() && j[q].is_number()) {
              j[q] = number();
              break;
            }
          }
          if (j[p].is_number()) j[p] = number();
          break;
        }
        case 7: v = deep(); break;
        case 8: v = std::string(pick(2) ? 100000 : 300, static_cast<char>('a' + pick(26))); break;
        default: {  // a non-finite number or an overflowing literal, written as text
          const std::string marker = "\"__FUZZ__\"";
          v = "__FUZZ__";
          std::string t = j.dump(1);
          static const std::vector<std::string> literals = {"NaN", "Infinity", "-inf", "1e999", "-1e400", "nan"};
          t.replace(t.find(marker), marker.size(), literals[pick(static_cast<int>(literals.size()))]);
          return t;
        }
      }
    }
    return j.dump(1);
  }

 private:
  std::mt19937 rng_;
};

/// An exit-2 message names what was wrong: a quoted key, name or value, a location in the
/// scene (bodies[1], solver.atol), the coordinate or byte position measured, an option.
bool namesSomething(const std::string& err) {
  for (const char* mark : {"\"", "'", "[", "solver.", "analysis", "byte", "option", "(", "JSON"}) {
    if (err.find(mark, std::string("flexmbd: error: ").size()) != std::string::npos) return true;
  }
  return false;
}

class Fuzz : public Cli {
 protected:
  /// Runs a whole shell command line (the binary named in it), output captured.
  CliResult runRaw(const std::string& commandLine) const {
    const fs::path out = dir_ / "cli_stdout.txt", err = dir_ / "cli_stderr.txt";
    const int rc = std::system((commandLine + " >" + shellQuote(out.string()) + " 2>" + shellQuote(err.string())).c_str());
    CliResult r;
    r.status = (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
  }
};

TEST_F(Fuzz, DamagedScenesOfEverySubcommand) {
  const char* seedEnv = std::getenv("FLEXMBD_FUZZ_SEED");
  const char* casesEnv = std::getenv("FLEXMBD_FUZZ_CASES");
  const int cases = casesEnv ? std::atoi(casesEnv) : kCases;
  Generator gen(seedEnv ? static_cast<unsigned>(std::strtoul(seedEnv, nullptr, 10)) : kSeed);
  std::vector<json> bases;
  for (const Base& b : kBases) bases.push_back(json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + b.file)));
  int counts[3] = {0, 0, 0};
  double slowest = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int c = 0; c < cases; ++c) {
    const int b = gen.pick(static_cast<int>(kBases.size()));
    const std::string text = gen.damage(bases[b]);
    const fs::path scene = dir_ / "case.json";
    std::ofstream(scene, std::ios::binary | std::ios::trunc) << text;
    const fs::path out = dir_ / "out";
    const auto t0 = std::chrono::steady_clock::now();
    const CliResult r = runRaw("timeout -s KILL " + std::to_string(kTimeLimitSeconds) + " " + shellQuote(FLEXMBD_CLI) +
                            " " + kBases[b].command + " " + shellQuote(scene.string()) + " --out " +
                            shellQuote(out.string()));
    slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    const std::string label = "case " + std::to_string(c) + " (" + kBases[b].command + " " + kBases[b].file + ")";
    bool ok = r.status >= 0 && r.status <= 2;
    EXPECT_TRUE(ok) << label << ": exit status " << r.status << " (137: killed at the time limit; "
                    << "-1 or 128+: a crash)\n" << r.err.substr(0, 500);
    if (r.status == 0) {
      const fs::path csv = out / (kBases[b].command == "run" ? "results.csv" : "kinematics.csv");
      std::string data = readFile(csv);
      for (char& ch : data) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      const bool finite = data.find("nan") == std::string::npos && data.find("inf") == std::string::npos;
      EXPECT_TRUE(finite) << label << ": exit 0 with a non-finite value in " << csv;
      ok = ok && finite;
    }
    if (r.status == 2) {
      const bool oneLine = IsOneErrorLine(r.err) && r.err.size() < 1100;
      EXPECT_TRUE(oneLine) << label << ": " << r.err.substr(0, 500);
      EXPECT_TRUE(namesSomething(r.err)) << label << ": the message names nothing: " << r.err;
      ok = ok && oneLine && namesSomething(r.err);
    }
    if (r.status >= 0 && r.status <= 2) ++counts[r.status];
    if (!ok && std::getenv("FLEXMBD_FUZZ_KEEP")) {
      std::ofstream(fs::temp_directory_path() / ("flexmbd_fuzz_case_" + std::to_string(c) + ".json"),
                    std::ios::binary) << text;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "fuzz: " << cases << " cases in " << seconds << " s (slowest " << slowest << " s): exit 0: " << counts[0]
            << ", exit 1: " << counts[1] << ", exit 2: " << counts[2] << std::endl;
  // The generator must reach every outcome, or it tests less than it claims.
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[2], cases / 2);
}

}  // namespace
