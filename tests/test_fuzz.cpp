// Fuzz test of the command line ("Kept fixed"): a seeded
// generator damages every example scene (planar, spatial rigid and flexible, tensegrity,
// kinematics) and variants of them that use the keys the examples leave out (Craig-Bampton
// and modes keys, beam theories, arrays of placed shapes, geometry, bushings placed in the
// world) — deleted keys, wrong types, huge, tiny and non-finite numbers, deep nesting,
// truncated and binary files, long and hostile names, keys of other objects inserted —
// and runs `flexmbd run`, `kinematics` or `modes` on each (with damaged options now and
// then), then, one case in kSummaryEvery, `flexmbd summary` and, one in kPlotEvery,
// `flexmbd plot` on the output folder (sometimes with its summary.json or results damaged). A second test damages the
// study files of `flexmbd-study` the same way. Every case must end by itself or stop on
// SIGTERM at its time limit (below), with exit status 0, 1 or 2; never exit 0 with a
// non-finite number or one beyond 1e100 in its results (results.csv, kinematics.csv,
// modes.csv, mode_shapes.csv, summary.json) or, for `modes`, without a mode; an exit-2
// message is one line naming what was wrong; no Python traceback from plot or study.
// Reproduce a case: FLEXMBD_FUZZ_KEEP=1 keeps the scene (and study file) of each failed
// case in /tmp (flexmbd_fuzz_case_N.json, flexmbd_fuzz_study_N.json).
// Explore further: FLEXMBD_FUZZ_SEED=n and FLEXMBD_FUZZ_CASES=n change the seed and count;
// FLEXMBD_FUZZ_TIME_SCALE=x multiplies every time limit (a sanitizer build: 10);
// FLEXMBD_FUZZ_WRAPPER runs the binary under a memory checker (cli() below);
// FLEXMBD_FUZZ_LOG=file appends one line per process (exit status, seconds, case).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "cli_fixture.hpp"
#include "scene/scene_keys.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Number of damaged scenes and the seed of the generator: 400 cases take about 50 s in
// Release on the 2-core machine loaded by two other builds (most are input errors, found
// in milliseconds); the study test runs kCases / kStudyShare studies (about 10 s: each a
// Python start).
constexpr int kCases = 400;
constexpr unsigned kSeed = 20261123;
constexpr int kSummaryEvery = 4;  // one case in 4 also runs flexmbd summary on its output folder
constexpr int kPlotEvery = 25;    // one case in 25 also plots it (a Python start)
constexpr int kStudyShare = 25;  // 400 scenes: 16 study files

// Time limit of a process: kMinSeconds, times FLEXMBD_FUZZ_TIME_SCALE if
// set (a sanitizer build, a slow machine). A damaged scene may legitimately run much longer
// (t_end, output_step or tolerances mutated): at its limit a process gets SIGTERM and
// counts as "stopped at its limit", not a failure, as long as it then ends within
// kGraceSeconds; one still running then is killed and is a hang (a failure). A process
// stopped at the floor is run again with kTimeFactor times the time the same command takes
// on the undamaged input, measured then (once per scene and command, in the same run of
// the test: a loaded machine measures longer), if that is longer: so slow examples get
// their room and the fast majority costs no measurement.
constexpr double kTimeFactor = 10.0;
constexpr double kMinSeconds = 5.0;
constexpr double kGraceSeconds = 10.0;

// ----- the scenes ------------------------------------------------------------------------

/// A base scene: an example, optionally with some values set (JSON pointer -> value) to use
/// keys no example uses.
struct Variant {
  std::string file;
  std::string label;
  std::vector<std::pair<std::string, json>> edits;
};

std::vector<Variant> variants() {
  std::vector<Variant> v;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(std::string(FLEXMBD_SOURCE_DIR) + "/examples")) {
    if (e.path().extension() == ".json") files.push_back(e.path().filename().string());
  }
  std::sort(files.begin(), files.end());  // the generator's choices do not depend on the directory order
  for (const std::string& f : files) {
    if (f.rfind("study_", 0) != 0) v.push_back({f, f, {}});  // study files: the second test
  }
  const json reduced = {{"modes", 4}, {"reduction", "craig_bampton"}, {"interface_nodes", {0, 8}},
                        {"inertia_modes", true}, {"beam_theory", "rayleigh"}};
  Variant cb3{"spatial_slider_crank_elastic.json", "spatial_slider_crank_elastic.json + craig_bampton", {}};
  Variant cb2{"slider_crank_elastic.json", "slider_crank_elastic.json + craig_bampton", {}};
  for (auto it = reduced.begin(); it != reduced.end(); ++it) {
    cb3.edits.push_back({"/bodies/1/" + it.key(), it.value()});
    cb2.edits.push_back({"/bodies/1/" + it.key(), it.key() == "modes" ? json(2) : it.value()});
  }
  v.push_back(cb3);
  v.push_back(cb2);
  v.push_back({"spinning_blade.json",
               "spinning_blade.json + timoshenko",
               {{"/bodies/0/beam_theory", "timoshenko"},
                {"/bodies/0/section/shear_factor_y", 0.8333},
                {"/bodies/0/section/shear_factor_z", 0.8333}}});
  // shapes placed by offset and orientation (balanced: the centre of mass stays the frame's
  // origin), geometry for viewing, bushings by world frame and by body frames
  const json shapes = json::parse(R"([
    {"type": "box", "size": [0.2, 0.02, 0.02], "density": 7800},
    {"type": "sphere", "radius": 0.02, "mass": 0.1, "offset": [0.1, 0, 0]},
    {"type": "sphere", "radius": 0.02, "mass": 0.1, "offset": [-0.1, 0, 0]},
    {"type": "cylinder", "radius": 0.01, "length": 0.05, "axis": "x", "density": 7800,
     "orientation": {"axis": [0, 0, 1], "angle": 0.5}}])");
  const json geometry = json::parse(R"([
    {"type": "box", "size": [0.5, 0.02, 0.02]},
    {"type": "tube", "outer_radius": 0.02, "inner_radius": 0.01, "length": 0.03, "axis": "z",
     "offset": [0.25, 0, 0], "orientation": {"quaternion": [1, 0, 0, 0]}}])");
  const json bushings = json::parse(R"([
    {"name": "mount", "type": "bushing", "bodies": ["ground", "rocker"],
     "world": {"point": [0.5, 0.2, 0], "axis": [0, 0, 1]},
     "stiffness": [0, 0, 0, 0, 0, 10], "damping": [0, 0, 0, 0, 0, 0.1]},
    {"name": "mount2", "type": "bushing", "bodies": ["crank", "coupler"],
     "frames": [{"point": [0.1, 0, 0]}, {"point": [-0.25, 0, 0]}], "stiffness": [0, 0, 0, 0, 0, 1]}])");
  v.push_back({"spatial_four_bar.json",
               "spatial_four_bar.json + shapes, geometry, bushings",
               {{"/bodies/0/shape", shapes}, {"/bodies/1/geometry", geometry}, {"/forces", bushings}}});
  return v;
}

enum class Model { Multibody, Kinematics, Tensegrity };

Model modelOf(const json& scene) {
  if (scene.contains("analysis")) return Model::Kinematics;
  if (scene.value("model", "") == "tensegrity") return Model::Tensegrity;
  return Model::Multibody;
}

/// Every value of a JSON tree, as JSON pointers.
void collectPointers(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) collectPointers(*it, at / it.key(), out);
  } else if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) collectPointers(j[k], at / k, out);
  }
}

/// Every key some scene reader accepts (scene/scene_keys.hpp): inserted into random objects.
std::vector<std::string> sceneKeys() {
  std::vector<std::string> keys;
  for (const auto& [id, list] : flexmbd::scenekeys::allObjects()) keys.insert(keys.end(), list->begin(), list->end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

/// The keys of study files (python/flexmbd/study.py).
const std::vector<std::string> kStudyKeys = {
    "name",   "scene", "overrides", "axes",  "combine", "samples", "outputs", "plot", "key",    "values", "range",
    "count",  "spacing", "summary", "max_abs", "max",   "min",     "final",   "at",   "after",  "functions",
    "x",      "y",     "group",     "file",  "title",   "log_x",   "log_y",   "column", "t",    "seed"};

/// Names that break files, paths, shells, CSV and plots: for every "name" and every name
/// referring to an object.
const std::vector<std::string> kHostileNames = {
    "a,b", "x\ny", "", " ", "ground", "a\"b", "a'b", "../../x", "/tmp/x", "nan", "inf", "-1e999", "t",
    "\xc3\xa9t\xc3\xa9", "a b", "a;b", std::string(65, 'n'), "-", "\t", "a\\b", "$(touch x)", "%s%n", "\x01",
    "CON", "rod.x", "\xff\xfe", "mode_1", "*", "velocity"};

/// Words the readers take as values (types, enumerations): with key insertion they reach
/// the branches of every reader.
const std::vector<std::string> kWords = {
    "craig_bampton", "normal",      "rayleigh",   "timoshenko", "euler_bernoulli", "box",       "sphere",
    "cylinder",      "tube",        "x",          "y",          "z",               "clamped",   "free_free",
    "pinned_pinned", "radau5",      "ali3p",      "ida",        "auto",            "klu",       "dense",
    "bushing",       "revolute",    "spherical",  "universal",  "planar",          "cylindrical", "fixed",
    "prismatic",     "rigid",       "flexible",   "flexible_invariants", "energy", "point",     "deflection",
    "resolve",       "refuse",      "ggl",        "index1",     "index3",          "constant_speed", "harmonic",
    "tabulated",     "spin_up",     "polynomial", "constant",   "massless_cables", "time_stepping", "joint_angle",
    "body_angle",    "applied_load", "spring_damper", "tensegrity", "free", "slider", "link_angle", "grid", "zip",
    "random",        "log",         "linear"};

class Generator {
 public:
  Generator(unsigned seed, std::vector<std::string> keys) : rng_(seed), keys_(std::move(keys)) {}
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  template <class T>
  const T& any(const std::vector<T>& v) {
    return v[pick(static_cast<int>(v.size()))];
  }

  json number() {
    static const std::vector<double> values = {1e308, -1e308, 1e100, -1e100, 1e99, 1e-308, 5e-324, -5e-324,
                                               0.0,   -0.0,   -1.0,  1e-300, 2147483648.0, 9.3e18, 1e15, 0.5,
                                               3.0,   1e-15,  -1e-3, 123456789.0, 8.0, 2.0, 1.0};
    return any(values);
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
  /// A value as a reader might take it for any key: numbers, vectors, words, flags, shapes,
  /// frames, or a piece of the same scene.
  json plausible(const json& scene) {
    switch (pick(8)) {
      case 0: return number();
      case 1: return any(std::vector<json>{{0, 1}, {0, 8}, {1, 0, 0}, {0, 0, 1}, {1, 2, 3, 4, 5, 6}, {{1, 0}, {0, 1}}});
      case 2: return any(kWords);
      case 3: return pick(2) == 1;
      case 4: return json::object({{"type", any(std::vector<std::string>{"box", "sphere", "cylinder", "tube"})},
                                   {"size", {0.1, 0.1, 0.1}}, {"radius", 0.05}, {"length", 0.1}, {"mass", 1.0},
                                   {"offset", {0.0, 0.1, 0.0}}});
      case 5: return json::object({{"point", {0, 0, 0}}, {"axis", {0, 0, 1}}});
      case 6: return static_cast<int>(pick(20)) - 2;
      default: {
        std::vector<json::json_pointer> ptrs;
        collectPointers(scene, json::json_pointer(), ptrs);
        return scene[any(ptrs)];
      }
    }
  }

  /// A file's text damaged as bytes: truncated, or binary garbage alone or spliced in.
  std::string damageText(const std::string& text) {
    if (pick(2) == 0 || text.empty()) return text.substr(0, pick(static_cast<int>(text.size()) + 1));
    std::string bytes(1 + pick(400), '\0');
    for (char& c : bytes) c = static_cast<char>(pick(256));
    if (pick(2)) return bytes;
    const std::size_t at = pick(static_cast<int>(text.size()));
    return text.substr(0, at) + bytes + text.substr(at);
  }

  /// The text of one damaged JSON file.
  std::string damage(const json& base) {
    const int kind = pick(12);
    const std::string text = base.dump(1);
    if (kind <= 1) return damageText(text);
    if (kind == 2) {  // nesting far beyond any limit, as text
      const int depth = pick(2) ? 100000 : 70;
      const std::string d = std::string(depth, '[') + std::string(depth, ']');
      return pick(2) ? d : "{\"name\": " + d + "}";
    }
    json j = base;
    std::vector<std::pair<std::string, std::string>> raw;  // markers and the literals they stand for
    const int edits = 1 + pick(3);
    for (int e = 0; e < edits; ++e) {
      std::vector<json::json_pointer> ptrs;
      collectPointers(j, json::json_pointer(), ptrs);
      const json::json_pointer p = any(ptrs);
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
            const json::json_pointer q = any(ptrs);
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
        case 10: {  // a hostile name: a "name" if there is one, else any string (a name referred to)
          std::vector<json::json_pointer> names, strings;
          for (const auto& q : ptrs) {
            if (!q.empty() && j[q].is_string()) (q.back() == "name" ? names : strings).push_back(q);
          }
          const auto& from = !names.empty() && pick(3) ? names : strings;
          if (from.empty()) break;
          if (pick(4) == 0 && !names.empty()) {  // the name of another object (duplicates)
            j[any(from)] = j[any(names)];
          } else {  // written as raw bytes after the dump (nlohmann refuses invalid UTF-8)
            const std::string marker = "__FUZZ_NAME_" + std::to_string(raw.size()) + "__";
            j[any(from)] = marker;
            raw.emplace_back("\"" + marker + "\"", jsonLiteral(any(kHostileNames)));
          }
          break;
        }
        case 11: {  // a key some reader accepts, inserted into an object (reaches every key)
          std::vector<json::json_pointer> objects;
          for (const auto& q : ptrs) {
            if (j[q].is_object()) objects.push_back(q);
          }
          j[any(objects)][any(keys_)] = plausible(j);
          break;
        }
        default: {  // a non-finite number or an overflowing literal, written as text
          const std::string marker = "\"__FUZZ__\"";
          v = "__FUZZ__";
          std::string t = j.dump(1);
          static const std::vector<std::string> literals = {"NaN", "Infinity", "-inf", "1e999", "-1e400", "nan"};
          t.replace(t.find(marker), marker.size(), any(literals));
          return withRaw(t, raw);
        }
      }
    }
    return withRaw(j.dump(1), raw);
  }

  /// text with each marker replaced by its literal.
  static std::string withRaw(std::string text, const std::vector<std::pair<std::string, std::string>>& raw) {
    for (const auto& [marker, literal] : raw) {
      const auto at = text.find(marker);
      if (at != std::string::npos) text.replace(at, marker.size(), literal);
    }
    return text;
  }
  /// A JSON string literal of s, its bytes as they are (invalid UTF-8 included).
  static std::string jsonLiteral(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
      if (c == '"' || c == '\\') {
        out += '\\';
        out += c;
      } else if (static_cast<unsigned char>(c) < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
        out += buf;
      } else {
        out += c;
      }
    }
    return out + "\"";
  }

  /// Extra command-line options, sometimes damaged (one case in four has any).
  std::string options(const std::string& command, const json& scene) {
    if (pick(4) != 0) return "";
    static const std::vector<std::string> values = {"0", "-1", "3", "1e-300", "1e999", "nan", "abc", "0.01", ""};
    const std::string v = shellQuote(any(values));
    if (command == "run") {
      return any(std::vector<std::string>{"--vtk", "--t-end " + v, "--rtol " + v, "--atol " + v, "--format hdf5",
                                          "--format " + v});
    }
    if (command == "kinematics") {
      return any(std::vector<std::string>{"--steps " + v, "--tolerance " + v, "--corrector modified_newton"});
    }
    if (command == "modes") {
      std::string driver = "motor";
      if (scene.is_object() && scene.contains("drivers") && scene["drivers"].is_array() && !scene["drivers"].empty() &&
          scene["drivers"][0].is_object() && scene["drivers"][0].value("name", json()).is_string()) {
        driver = scene["drivers"][0]["name"].get<std::string>();
      }
      return any(std::vector<std::string>{"--count " + v, "--at " + v, "--steady", "--solver dense", "--solver sparse",
                                          "--sweep " + shellQuote(driver + ":0:50:3"), "--sweep " + v});
    }
    // plot
    return any(std::vector<std::string>{"--columns " + shellQuote(any(kHostileNames)), "--x " + shellQuote(any(kHostileNames)),
                                        "--deg", "--title " + shellQuote(std::string(400, 't')), "--labels a,b",
                                        "--x t --deg", "--out " + v});
  }

 private:
  std::mt19937 rng_;
  std::vector<std::string> keys_;
};

// ----- what every case must satisfy ------------------------------------------------------

/// An exit-2 message names what was wrong: a quoted key, name or value, a location in the
/// scene (bodies[1], solver.atol), the coordinate or byte position measured, an option, a
/// results file.
bool namesSomething(const std::string& err, const std::string& prefix) {
  for (const char* mark : {"\"", "'", "[", "solver.", "analysis", "byte", "option", "--", "(", "JSON", ".csv"}) {
    if (err.find(mark, prefix.size()) != std::string::npos) return true;
  }
  return false;
}

/// One line starting with prefix ("flexmbd: error:", "flexmbd-study: error:").
bool isOneErrorLine(const std::string& err, const std::string& prefix) {
  const auto nl = err.find('\n');
  return err.rfind(prefix, 0) == 0 && nl != std::string::npos && nl + 1 == err.size() && err.size() < 1100;
}

/// The rows of a CSV file (RFC 4180: quoted fields may hold commas, quotes and newlines).
std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string field;
  bool quoted = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (quoted) {
      if (c == '"' && k + 1 < text.size() && text[k + 1] == '"') {
        field += '"';
        ++k;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().push_back(field);
      field.clear();
    } else if (c == '\n') {
      rows.back().push_back(field);
      field.clear();
      rows.emplace_back();
    } else if (c != '\r') {
      field += c;
    }
  }
  if (!field.empty() || !rows.back().empty()) rows.back().push_back(field);
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

/// The first value of a results table's data rows that is not finite or beyond 1e100 in
/// magnitude, with its row and column ("" if none). firstColumn: 1 skips a column of names.
std::string absurdNumberInCsv(const fs::path& file, std::size_t firstColumn = 0) {
  const auto rows = parseCsv(readFile(file));
  for (std::size_t r = 1; r < rows.size(); ++r) {
    for (std::size_t c = firstColumn; c < rows[r].size(); ++c) {
      const std::string& f = rows[r][c];
      std::string lower = f;
      for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      char* end = nullptr;
      const double x = std::strtod(f.c_str(), &end);
      const bool number = !f.empty() && end == f.c_str() + f.size();
      if ((number && !(std::abs(x) <= 1e100)) || (!number && (lower.find("nan") != std::string::npos ||
                                                              lower.find("inf") != std::string::npos))) {
        const std::string column = c < rows[0].size() ? rows[0][c] : std::to_string(c);
        return file.filename().string() + " row " + std::to_string(r) + " column '" + column + "': " + f;
      }
    }
  }
  return "";
}

/// The first number of summary.json beyond 1e100 in magnitude ("" if none; a file that is
/// not JSON — NaN written as a number — is reported too).
std::string absurdNumberInJson(const fs::path& file) {
  if (!fs::exists(file)) return "";
  const json j = json::parse(readFile(file), nullptr, false);
  if (j.is_discarded()) return file.filename().string() + " is not valid JSON";
  std::vector<json::json_pointer> ptrs;
  collectPointers(j, json::json_pointer(), ptrs);
  for (const auto& p : ptrs) {
    if (j[p].is_number_float() && !(std::abs(j[p].get<double>()) <= 1e100)) {
      return file.filename().string() + " " + p.to_string() + ": " + j[p].dump();
    }
  }
  return "";
}

/// text on one line (a label holding a hostile option or name).
std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text.substr(0, 300);
}

/// The outcome of one process of a case.
enum class Outcome { Exit0, Exit1, Exit2, Stopped, Hang, Crash };

struct Tally {
  std::map<Outcome, int> counts;
  int failures = 0;
  double slowest = 0.0;
  std::string line(int cases, double seconds) const {
    auto n = [&](Outcome o) { return counts.count(o) ? counts.at(o) : 0; };
    return std::to_string(cases) + " cases in " + std::to_string(static_cast<int>(seconds)) + " s (slowest process " +
           std::to_string(slowest).substr(0, 5) + " s): processes exit 0: " + std::to_string(n(Outcome::Exit0)) +
           ", exit 1: " + std::to_string(n(Outcome::Exit1)) + ", exit 2: " + std::to_string(n(Outcome::Exit2)) +
           ", stopped at their limit: " + std::to_string(n(Outcome::Stopped)) +
           ", hangs: " + std::to_string(n(Outcome::Hang)) + ", crashes: " + std::to_string(n(Outcome::Crash)) +
           "; failed cases: " + std::to_string(failures);
  }
};

double envDouble(const char* name, double otherwise) {
  const char* v = std::getenv(name);
  return v ? std::strtod(v, nullptr) : otherwise;
}

class Fuzz : public Cli {
 protected:
  struct Process {
    int status = -1;  ///< exit status of timeout(1): the command's, 124 stopped at the limit, 137 killed
    std::string out, err;
    double seconds = 0.0;
  };

  /// Runs a whole shell command line (the binary named in it), output captured, SIGTERM at
  /// limit seconds and SIGKILL kGraceSeconds later.
  Process runLimited(const std::string& commandLine, double limit) const {
    const fs::path out = dir_ / "cli_stdout.txt", err = dir_ / "cli_stderr.txt";
    const double grace = kGraceSeconds * timeScale();
    const std::string cmd = "timeout -k " + std::to_string(grace) + " -s TERM " + std::to_string(limit) + " " +
                            commandLine + " </dev/null >" + shellQuote(out.string()) + " 2>" + shellQuote(err.string());
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system(cmd.c_str());
    Process r;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.status = (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
  }

  static double timeScale() { return envDouble("FLEXMBD_FUZZ_TIME_SCALE", 1.0); }

  /// Runs commandLine within its time limit (above); key names the undamaged input whose
  /// run time undamaged() measures (in seconds) if the floor was too short; before() clears
  /// what the process writes, before each try.
  Process runCase(const std::string& commandLine, const std::string& key, const std::function<double()>& undamaged,
                  const std::function<void()>& before) {
    const double floor = kMinSeconds * timeScale();
    auto known = baseline_.find(key);
    double limit = known == baseline_.end() ? floor : std::max(floor, kTimeFactor * known->second * timeScale());
    before();
    Process r = runLimited(commandLine, limit);
    if (r.status == 124 && known == baseline_.end()) {
      const double measured = undamaged();
      baseline_[key] = measured;
      if (kTimeFactor * measured * timeScale() > limit) {
        before();
        r = runLimited(commandLine, kTimeFactor * measured * timeScale());
      }
    }
    return r;
  }

  /// Seconds the shell command line takes (the undamaged input of a case), at most 600.
  double timed(const std::string& commandLine) const { return runLimited(commandLine, 600.0).seconds; }

  /// Checks one process against the rules above (prefix: the tool's error prefix), counts
  /// it, and returns false (with the failures reported) if it broke one.
  bool check(const std::string& label, const Process& r, const std::string& prefix, Tally& tally) {
    tally.slowest = std::max(tally.slowest, r.seconds);
    Outcome o = Outcome::Crash;
    if (r.status >= 0 && r.status <= 2) o = static_cast<Outcome>(r.status);
    if (r.status == 124) o = Outcome::Stopped;
    if (r.status == 137) o = Outcome::Hang;
    ++tally.counts[o];
    if (const char* log = std::getenv("FLEXMBD_FUZZ_LOG")) {  // one line per process: exit status, seconds, case
      std::ofstream(log, std::ios::app) << r.status << " " << r.seconds << " " << oneLine(label) << "\n";
    }
    bool ok = true;
    if (o == Outcome::Crash || o == Outcome::Hang) {
      ADD_FAILURE() << label << ": exit status " << r.status
                    << (o == Outcome::Hang ? " (still running " + std::to_string(kGraceSeconds) + " s after SIGTERM)"
                                           : " (a crash)")
                    << "\n" << r.err.substr(0, 500);
      ok = false;
    }
    if (r.err.find("Traceback (most recent call last)") != std::string::npos) {
      ADD_FAILURE() << label << ": a Python traceback\n" << r.err.substr(0, 3000);
      ok = false;
    }
    if (o == Outcome::Exit2 && !(isOneErrorLine(r.err, prefix) && namesSomething(r.err, prefix))) {
      ADD_FAILURE() << label << ": exit 2 without one line '" << prefix << " ...' naming what was wrong:\n"
                    << r.err.substr(0, 500);
      ok = false;
    }
    return ok;
  }

  /// After an exit 0: the written results hold only finite numbers of sane magnitude (and
  /// modes.csv at least one mode).
  bool checkResults(const std::string& label, const std::string& command, const fs::path& out) {
    std::vector<std::string> problems;
    auto add = [&](const std::string& p) {
      if (!p.empty()) problems.push_back(p);
    };
    if (command == "run" || command == "kinematics") {
      const fs::path csv = out / (command == "run" ? "results.csv" : "kinematics.csv");
      if (fs::exists(csv)) add(absurdNumberInCsv(csv));
      add(absurdNumberInJson(out / "summary.json"));
    } else if (command == "modes") {  // with --sweep: campbell.csv, one row per speed
      const fs::path table = out / (fs::exists(out / "campbell.csv") ? "campbell.csv" : "modes.csv");
      if (parseCsv(readFile(table)).size() < 2) add(table.filename().string() + " holds no mode");
      add(absurdNumberInCsv(table));
      if (fs::exists(out / "mode_shapes.csv")) add(absurdNumberInCsv(out / "mode_shapes.csv", 1));
    }
    for (const auto& p : problems) ADD_FAILURE() << label << ": exit 0 with " << p;
    return problems.empty();
  }

  int cases() const {
    const char* v = std::getenv("FLEXMBD_FUZZ_CASES");
    return v ? std::atoi(v) : kCases;
  }
  unsigned seed() const {
    const char* v = std::getenv("FLEXMBD_FUZZ_SEED");
    return v ? static_cast<unsigned>(std::strtoul(v, nullptr, 10)) : kSeed;
  }
  static void keep(const std::string& name, const std::string& text) {
    if (std::getenv("FLEXMBD_FUZZ_KEEP")) std::ofstream(fs::temp_directory_path() / name, std::ios::binary) << text;
  }

  std::map<std::string, double> baseline_;
};

/// The binary, behind FLEXMBD_FUZZ_WRAPPER if set: a memory checker on the Release build,
/// e.g. "valgrind -q --error-exitcode=99" (an error is then an exit status outside 0-2: a
/// failure), with FLEXMBD_FUZZ_TIME_SCALE=30.
std::string cli() {
  const char* wrapper = std::getenv("FLEXMBD_FUZZ_WRAPPER");
  return (wrapper ? std::string(wrapper) + " " : std::string()) + shellQuote(FLEXMBD_CLI);
}

TEST_F(Fuzz, DamagedScenesOfEverySubcommand) {
  const int n = cases();
  Generator gen(seed(), sceneKeys());
  const std::vector<Variant> bases = variants();
  std::vector<json> scenes;
  for (const Variant& b : bases) {
    json j = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + b.file));
    for (const auto& [ptr, value] : b.edits) j[json::json_pointer(ptr)] = value;
    scenes.push_back(j);
  }
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  for (int c = 0; c < n; ++c) {
    const int b = gen.pick(static_cast<int>(bases.size()));
    const Model model = modelOf(scenes[b]);
    const std::string command = model == Model::Kinematics ? "kinematics"
                                : model == Model::Tensegrity ? "run"
                                                             : (gen.pick(4) == 0 ? "modes" : "run");
    const std::string text = gen.damage(scenes[b]);
    const std::string options = gen.options(command, scenes[b]);
    const bool summary = gen.pick(kSummaryEvery) == 0, plot = gen.pick(kPlotEvery) == 0;
    const bool damageOutput = gen.pick(4) == 0;
    const std::string plotOptions = plot ? gen.options("plot", scenes[b]) : "";
    const fs::path scene = dir_ / "case.json", out = dir_ / "out";
    std::ofstream(scene, std::ios::binary | std::ios::trunc) << text;
    const std::string label = "case " + std::to_string(c) + " (" + command + " " + bases[b].label +
                              (options.empty() ? "" : " " + options) + ")";
    // the undamaged scene's own run, its time the measure of the damaged one's limit
    const fs::path baseOut = dir_ / ("base_" + std::to_string(b) + "_" + command);
    auto undamaged = [&] {
      const fs::path file = dir_ / ("base_" + std::to_string(b) + ".json");
      std::ofstream(file) << scenes[b].dump(1);
      fs::remove_all(baseOut);
      return timed(cli() + " " + command + " " + shellQuote(file.string()) + " --quiet --out " +
                   shellQuote(baseOut.string()));
    };
    const Process r = runCase(cli() + " " + command + " " + shellQuote(scene.string()) + " --out " +
                                  shellQuote(out.string()) + " " + options,
                              std::to_string(b) + " " + command, undamaged, [&] { fs::remove_all(out); });
    bool ok = check(label, r, "flexmbd: error:", tally);
    if (r.status == 0) ok = checkResults(label, command, out) && ok;

    // summary and plot on whatever the run left (nothing, a failed run, a stopped one),
    // sometimes with its summary.json or results.csv damaged
    if (summary) {
      const fs::path file = out / "summary.json";
      if (damageOutput && fs::exists(file)) {
        const json j = json::parse(readFile(file), nullptr, false);
        const std::string damaged = j.is_discarded() ? gen.damageText(readFile(file)) : gen.damage(j);
        std::ofstream(file, std::ios::binary | std::ios::trunc) << damaged;
      }
      const Process p = runLimited(cli() + " summary " + shellQuote(out.string()), kMinSeconds * timeScale());
      ok = check(label + ", then summary", p, "flexmbd: error:", tally) && ok;
    }
    if (plot) {
      for (const char* name : {"results.csv", "kinematics.csv"}) {
        const fs::path file = out / name;
        if (damageOutput && fs::exists(file)) {
          const std::string damaged = gen.damageText(readFile(file));
          std::ofstream(file, std::ios::binary | std::ios::trunc) << damaged;
        }
      }
      auto undamagedPlot = [&] {
        undamaged();
        return timed(cli() + " plot " + shellQuote(baseOut.string()) + " --out " +
                     shellQuote((dir_ / "base_plot.png").string()));
      };
      const Process p = runCase(cli() + " plot " + shellQuote(out.string()) + " " + plotOptions,
                                std::to_string(b) + " plot " + command, undamagedPlot, [] {});
      ok = check(label + ", then plot " + plotOptions, p, "flexmbd: error:", tally) && ok;
    }
    if (!ok) {
      ++tally.failures;
      keep("flexmbd_fuzz_case_" + std::to_string(c) + ".json", text);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "fuzz: " << tally.line(n, seconds) << std::endl;
  // The generator must reach every outcome, or it tests less than it claims.
  EXPECT_GT(tally.counts[Outcome::Exit0], 0);
  EXPECT_GT(tally.counts[Outcome::Exit2], n / 2);
}

/// The study files of flexmbd-study, damaged the same way: each must end (serially, its
/// points bounded by the scene's t_end and the time limit), exit 0 or 2 (exit 2: one line
/// "flexmbd-study: error: ..."), never with a traceback, and an exit 0 must have recorded
/// every point with a status.
TEST_F(Fuzz, DamagedStudyFiles) {
#ifndef FLEXMBD_STUDY
  GTEST_SKIP() << "built without the Python module";
#else
  const int n = std::max(1, cases() / kStudyShare);
  Generator gen(seed() + 1, kStudyKeys);
  const std::string examples = std::string(FLEXMBD_SOURCE_DIR) + "/examples/";
  // points that succeed, fail on input (a negative mass), fail in the solver (max_steps 5),
  // a grid, a zip of strings, random samples of a log range
  const std::vector<json> studies = {
      {{"name", "fuzz-rigid"},
       {"scene", examples + "slider_crank_rigid.json"},
       {"overrides", {{"solver", {{"t_end", 0.5}}}}},
       {"axes", {{{"name", "speed"}, {"key", "drivers[0].law.speed"}, {"values", {1.0, 2.0}}},
                 {{"name", "mass"}, {"key", "bodies[0].mass"}, {"values", {1.0, -1.0}}}}},
       {"outputs", {{"summary", {"steps"}}, {"max_abs", {"slider.x"}}, {"final", {"crank.theta"}}, {"after", 0.1},
                    {"at", {{{"column", "slider.x"}, {"t", 0.25}, {"name", "x_mid"}}}}}},
       {"plot", {{"x", "speed"}, {"y", {"max_abs(slider.x)", "x_mid"}}, {"group", "mass"}, {"file", "s.png"},
                 {"title", "fuzz"}, {"log_y", false}}}},
      {{"scene", examples + "slider_crank_elastic_demo_modal.json"},
       {"overrides", {{"solver.t_end", 0.005}}},
       {"axes", {{{"name", "integrator"}, {"key", "solver.integrator"}, {"values", {"ida", "radau5"}}},
                 {{"name", "max_steps"}, {"key", "solver.max_steps"}, {"values", {5, 100000}}}}},
       {"combine", "zip"},
       {"outputs", {{"max_abs", {"mid.uy"}}}},
       {"plot", {{"x", "max_steps"}, {"y", "max_abs(mid.uy)"}, {"group", "integrator"}, {"log_x", true}}}},
      {{"scene", examples + "spatial_four_bar.json"},
       {"overrides", {{"solver", {{"t_end", 0.05}}}}},
       {"axes", {{{"key", "gravity[1]"}, {"range", {-20, -1}}, {"spacing", "linear"}},
                 {{"name", "density"}, {"key", "bodies[0].shape.density"}, {"range", {100, 10000}}, {"spacing", "log"}}}},
       {"combine", "random"},
       {"samples", {{"count", 3}, {"seed", 7}}},
       {"outputs", {{"summary", {"steps", "cpu_seconds"}}, {"min", {"crank.x"}}}}}};
  static const std::vector<std::string> kStatuses = {"ok", "failed", "input_error", "error"};
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  for (int c = 0; c < n; ++c) {
    const int b = gen.pick(static_cast<int>(studies.size()));
    const std::string text = gen.damage(studies[b]);
    const fs::path file = dir_ / "study.json", out = dir_ / "study_out";
    std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
    const std::string label = "study case " + std::to_string(c) + " (study " + std::to_string(b) + ")";
    const std::string study = shellQuote(FLEXMBD_STUDY);
    auto undamaged = [&] {
      const fs::path undamagedFile = dir_ / ("study_" + std::to_string(b) + ".json");
      std::ofstream(undamagedFile) << studies[b].dump(1);
      const fs::path undamagedOut = dir_ / ("study_" + std::to_string(b));
      fs::remove_all(undamagedOut);
      return timed(study + " " + shellQuote(undamagedFile.string()) + " --workers 0 --quiet --out " +
                   shellQuote(undamagedOut.string()));
    };
    const Process r = runCase(study + " " + shellQuote(file.string()) + " --workers 0 --quiet --out " +
                                  shellQuote(out.string()),
                              "study " + std::to_string(b), undamaged, [&] { fs::remove_all(out); });
    bool ok = check(label, r, "flexmbd-study: error:", tally);
    if (r.status == 0) {  // every point recorded with a status
      const auto rows = parseCsv(readFile(out / "study.csv"));
      const std::size_t col = rows.empty() ? 0 : static_cast<std::size_t>(
          std::find(rows[0].begin(), rows[0].end(), "status") - rows[0].begin());
      const bool hasStatus = !rows.empty() && col < rows[0].size();
      EXPECT_TRUE(hasStatus) << label << ": exit 0 without study.csv or its status column";
      ok = ok && hasStatus;
      for (std::size_t k = 1; hasStatus && k < rows.size(); ++k) {
        const bool known = col < rows[k].size() &&
                           std::find(kStatuses.begin(), kStatuses.end(), rows[k][col]) != kStatuses.end();
        EXPECT_TRUE(known) << label << ": study.csv row " << k << " has no known status";
        ok = ok && known;
      }
    }
    if (!ok) {
      ++tally.failures;
      keep("flexmbd_fuzz_study_" + std::to_string(c) + ".json", text);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "fuzz studies: " << tally.line(n, seconds) << std::endl;
#endif
}

}  // namespace
