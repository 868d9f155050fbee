/// @file
/// The strict JSON reading shared by every scene format (multibody, kinematics,
/// tensegrity): typed, checked access to the keys of one object, one-line errors
/// "<location>: <what is wrong>, got <what was found>", and the time-law objects.
#pragma once

#include <algorithm>
#include <cctype>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/magnitude_checks.hpp"
#include "core/number_text.hpp"
#include "core/time_law.hpp"
#include "core/types.hpp"

namespace flexmbd::jsonread {

using nlohmann::json;

/// Largest magnitude of a number in a scene file. The engine forms squares and products
/// of a few input values (speed^2 in accelerations, mass * speed^2 in energies, E I / L^3
/// in stiffnesses): 1e100 keeps them finite, and no physical quantity in SI units comes
/// near it (the mass of the observable universe is 1e53 kg).
constexpr double kMaxInputMagnitude = 1e100;

// ----- formatting ------------------------------------------------------------------

/// Longest text of a value or name quoted in an error message; longer ones are cut and
/// end in "...". A message must stay one readable line even for a 100 KB name.
constexpr std::size_t kMaxQuoted = 60;

/// `s` cut to at most `limit` characters, ending in "..." if it was cut (never inside
/// a UTF-8 sequence).
inline std::string shorten(const std::string& s, std::size_t limit = kMaxQuoted) {
  limit = std::max<std::size_t>(limit, 8);
  if (s.size() <= limit) return s;
  std::size_t n = limit - 3;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // continuation byte
  return s.substr(0, n) + "...";
}

/// Appends at most about `limit` characters of the JSON text of `v`: never serialises
/// more of a large or deep value than the message can show (the cost and the size of
/// the message are bounded whatever the value).
inline void appendBounded(std::string& out, const json& v, std::size_t limit, int depth = 0) {
  if (out.size() > limit) return;
  switch (v.type()) {
    case json::value_t::string: {
      const std::string part = shorten(v.get_ref<const std::string&>(), limit + 4 - std::min(limit, out.size()));
      out += json(part).dump(-1, ' ', false, json::error_handler_t::replace);
      return;
    }
    case json::value_t::array:
    case json::value_t::object: {
      const bool isObject = v.is_object();
      out += isObject ? '{' : '[';
      if (depth >= 8) {
        out += "...";
      } else {
        bool first = true;
        for (auto it = v.begin(); it != v.end(); ++it) {
          if (out.size() > limit) break;
          if (!first) out += ',';
          first = false;
          if (isObject) {
            out += json(shorten(it.key(), limit)).dump(-1, ' ', false, json::error_handler_t::replace);
            out += ':';
          }
          appendBounded(out, *it, limit, depth + 1);
        }
      }
      out += isObject ? '}' : ']';
      return;
    }
    default: out += v.dump(); return;
  }
}

/// "string \"abc\"", "number 3", "array [1,2]", "null", ... (long values shortened).
inline std::string describe(const json& v) {
  if (v.is_null()) return "null";
  if (v.is_number_float() && !std::isfinite(v.get<double>())) return "number " + fmt(v.get<double>());
  std::string d;
  appendBounded(d, v, kMaxQuoted);
  if (d.size() > kMaxQuoted) d = d.substr(0, kMaxQuoted - 3) + "...";
  switch (v.type()) {
    case json::value_t::string: return "string " + d;
    case json::value_t::boolean: return "boolean " + d;
    case json::value_t::array: return "array " + d;
    case json::value_t::object: return "object " + d;
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "number " + d;
    default: return d;
  }
}

/// Items of a list in a message: each shortened, at most 20 of them.
inline std::string join(const std::vector<std::string>& items) {
  constexpr std::size_t kMaxItems = 20;
  std::string out;
  for (std::size_t k = 0; k < items.size() && k < kMaxItems; ++k) out += (out.empty() ? "" : ", ") + shorten(items[k]);
  if (items.size() > kMaxItems) out += ", ... (" + std::to_string(items.size() - kMaxItems) + " more)";
  return out;
}

/// Deepest nesting of arrays and objects a scene file may have. The formats use at most
/// 5 levels (scene > "bodies" > body > "elastic_coordinates"... or a matrix's rows); 64
/// leaves room for any future key while keeping every recursive step over the parsed value
/// (copy, destruction, serialisation) far from the stack's limit.
constexpr int kMaxJsonDepth = 64;

/// Refuses JSON text nested deeper than kMaxJsonDepth before it is parsed (a file of
/// 100,000 '[' would otherwise exhaust the stack). Strings are skipped; the text need not
/// be valid JSON (the parser reports that). @throws InputError "<source>: ...".
inline void checkJsonNesting(const std::string& text, const std::string& source) {
  int depth = 0;
  bool inString = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (inString) {
      if (c == '\\') ++k;
      else if (c == '"') inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        throw InputError(source + ": JSON nested more than " + std::to_string(kMaxJsonDepth) +
                         " levels deep at byte " + std::to_string(k + 1) +
                         " (scene files need at most 5 levels of arrays and objects)");
      }
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    }
  }
}

/// A name or key in quotes, shortened to kMaxQuoted characters.
inline std::string inQuotes(const std::string& s) { return "\"" + shorten(s) + "\""; }

// ----- names -----------------------------------------------------------------------------

/// The one rule for every name a scene gives, in every format (bodies, joints, drivers,
/// forces, outputs; tensegrity nodes, struts, cables, loads; linkage nodes, links, inputs):
/// names become column names of results.csv and results.h5, VTK array names and Python
/// keys, and not all of these can quote a comma, quote or newline (docs/scene-format.md).
constexpr std::size_t kMaxNameLength = 64;
constexpr const char* kNameRule = "names are 1 to 64 characters, each an ASCII letter, a digit, '_' or '-'";

/// "" if `name` follows the rule; otherwise what breaks it ("has the character ',' at
/// position 2", "is empty", "is 100000 characters long").
inline std::string nameProblem(const std::string& name) {
  if (name.empty()) return "is empty";
  for (std::size_t k = 0; k < name.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(name[k]);
    if (std::isalnum(c) && c < 128) continue;
    if (c == '_' || c == '-') continue;
    char shown[40];
    if (c >= 32 && c < 127) std::snprintf(shown, sizeof shown, "the character '%c'", c);
    else if (c < 32 || c == 127) std::snprintf(shown, sizeof shown, "the control character 0x%02X", c);
    else std::snprintf(shown, sizeof shown, "the non-ASCII byte 0x%02X", c);  // UTF-8
    return "has " + std::string(shown) + " at position " + std::to_string(k + 1);
  }
  if (name.size() > kMaxNameLength) return "is " + std::to_string(name.size()) + " characters long";
  return "";
}

/// A name in a message: quoted JSON-style (a newline shows as \n), shortened.
inline std::string shownName(const std::string& name) {
  return json(shorten(name)).dump(-1, ' ', false, json::error_handler_t::replace);
}

/// @throws InputError "\<where\>: key "\<key\>": the name "a,b" has the character ',' at
/// position 2 (names are 1 to 64 characters, ...)" if `name` breaks the rule.
inline void checkName(const std::string& name, const std::string& key, const std::string& where) {
  const std::string problem = nameProblem(name);
  if (!problem.empty()) {
    throw InputError(where + ": key " + inQuotes(key) + ": the name " + shownName(name) + " " + problem + " (" +
                     kNameRule + ")");
  }
}

// ----- scene files -------------------------------------------------------------------------

/// Largest scene file read (64 MiB): the largest models the engine runs are a few MB of
/// JSON; a bound keeps a wrong path (a log, a disk image) from taking the memory.
constexpr std::uintmax_t kMaxSceneFileBytes = 64ull << 20;

/// The text of the scene file at `path`: a regular file of at most kMaxSceneFileBytes
/// (FIFOs, devices such as /dev/zero and directories are refused before any read).
/// One reader for every scene format and command. @throws InputError naming the path.
std::string readSceneFile(const std::string& path);

/// nlohmann's message without its "[json.exception.xxx.nnn] " prefix.
inline std::string plainMessage(const json::exception& e) {
  std::string m = e.what();
  if (!m.empty() && m[0] == '[') {
    const auto close = m.find("] ");
    if (close != std::string::npos) m = m.substr(close + 2);
  }
  return m;
}

// ----- reading one JSON object ---------------------------------------------------------

/// Typed, checked access to the keys of one JSON object at a location of the scene.
/// Every failure throws InputError("<location>: <message>").
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) fail("expected an object {...}, got " + describe(j_));
  }

  const std::string& where() const { return where_; }
  [[noreturn]] void fail(const std::string& message) const { throw InputError(where_ + ": " + message); }

  /// Adds the object's name to the location: `bodies[1]` -> `bodies[1] ("rod")`.
  /// Used as soon as a string name is found, so later messages carry it.
  void peekName() {
    const auto it = j_.find("name");
    if (it != j_.end() && it->is_string()) where_ += " (" + shownName(it->get<std::string>()) + ")";
  }

  /// Rejects keys not in `allowed`; `what` qualifies the list (" for a harmonic law").
  void allowOnly(const std::vector<std::string>& allowed, const std::string& what = "") const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end()) {
        fail("unknown key " + inQuotes(it.key()) + " (allowed keys" + what + ": " + join(allowed) + ")");
      }
    }
  }

  bool has(const std::string& key) const { return j_.contains(key); }

  const json& required(const std::string& key) const {
    const auto it = j_.find(key);
    if (it == j_.end()) fail("missing required key " + inQuotes(key));
    return *it;
  }

  // --- scalars ---
  double number(const std::string& key) const { return toNumber(required(key), key); }
  double number(const std::string& key, double fallback) const {
    return has(key) ? number(key) : fallback;
  }
  double positive(const std::string& key) const { return checkPositive(number(key), key); }
  double positive(const std::string& key, double fallback) const {
    return has(key) ? positive(key) : fallback;
  }
  double nonNegative(const std::string& key) const { return checkNonNegative(number(key), key); }
  double nonNegative(const std::string& key, double fallback) const {
    return has(key) ? nonNegative(key) : fallback;
  }

  std::string string(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_string()) fail("key " + inQuotes(key) + " must be a string, got " + describe(v));
    return v.get<std::string>();
  }
  std::string string(const std::string& key, const std::string& fallback) const {
    return has(key) ? string(key) : fallback;
  }
  /// A required name (of this object or of one it refers to) following the name rule
  /// (checkName).
  std::string name(const std::string& key) const {
    std::string s = string(key);
    checkName(s, key, where_);
    return s;
  }
  std::string name(const std::string& key, const std::string& fallback) const {
    return has(key) ? name(key) : fallback;
  }
  /// A required non-empty string that is not a name (a type, a model, a method).
  std::string nonEmptyString(const std::string& key) const {
    std::string s = string(key);
    if (s.empty()) fail("key " + inQuotes(key) + " must not be empty");
    return s;
  }

  bool boolean(const std::string& key, bool fallback) const {
    if (!has(key)) return fallback;
    const json& v = required(key);
    if (!v.is_boolean()) fail("key " + inQuotes(key) + " must be true or false, got " + describe(v));
    return v.get<bool>();
  }

  /// An integer in [minimum, maximum] (1e6 written as a float is accepted if integral).
  long integer(const std::string& key, long fallback, long minimum,
               long maximum = std::numeric_limits<int>::max()) const {
    if (!has(key)) return fallback;
    const json& v = required(key);
    long value = 0;
    if (v.is_number_integer() || v.is_number_unsigned()) {
      if (v.is_number_unsigned() &&
          v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<long>::max())) {
        fail("key " + inQuotes(key) + " is too large, got " + describe(v));
      }
      value = v.get<long>();
    } else if (v.is_number_float()) {
      const double d = toNumber(v, key);
      if (d != std::floor(d) || std::fabs(d) > 9.0e18) {
        fail("key " + inQuotes(key) + " must be an integer, got " + fmt(d));
      }
      value = static_cast<long>(d);
    } else {
      fail("key " + inQuotes(key) + " must be an integer, got " + describe(v));
    }
    if (value < minimum) {
      fail("key " + inQuotes(key) + " must be >= " + std::to_string(minimum) + ", got " + std::to_string(value));
    }
    if (value > maximum) {
      fail("key " + inQuotes(key) + " must be <= " + std::to_string(maximum) + ", got " + std::to_string(value));
    }
    return value;
  }

  // --- vectors ---
  Vec2 vec2(const std::string& key) const { return toVec2(required(key), key); }
  Vec2 vec2(const std::string& key, const Vec2& fallback) const {
    return has(key) ? vec2(key) : fallback;
  }

  /// [[xi, yi], [xj, yj]]
  std::array<Vec2, 2> pointPair(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_array() || v.size() != 2) {
      fail("key " + inQuotes(key) + " must be two points [[xi, yi], [xj, yj]], got " + describe(v));
    }
    return {toVec2(v[0], key + "[0]"), toVec2(v[1], key + "[1]")};
  }

  /// [nameI, nameJ]
  std::array<std::string, 2> namePair(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_array() || v.size() != 2 || !v[0].is_string() || !v[1].is_string()) {
      fail("key " + inQuotes(key) + " must be two body names [\"bodyI\", \"bodyJ\"], got " + describe(v));
    }
    for (int k = 0; k < 2; ++k) checkName(v[k].get<std::string>(), key + "[" + std::to_string(k) + "]", where_);
    return {v[0].get<std::string>(), v[1].get<std::string>()};
  }

  /// A non-empty array of finite numbers.
  std::vector<double> numbers(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_array() || v.empty()) {
      fail("key " + inQuotes(key) + " must be a non-empty array of numbers, got " + describe(v));
    }
    std::vector<double> out;
    out.reserve(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) out.push_back(toNumber(v[k], key + "[" + std::to_string(k) + "]"));
    return out;
  }

  /// A matrix written as an array of rows of numbers (all rows the same length).
  MatX matrix(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_array()) fail("key " + inQuotes(key) + " must be an array of rows [[...], ...], got " + describe(v));
    if (v.empty()) return MatX(0, 0);
    const std::size_t cols = v[0].is_array() ? v[0].size() : 0;
    MatX m(v.size(), cols);
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string row = key + "[" + std::to_string(i) + "]";
      if (!v[i].is_array() || v[i].size() != cols) {
        fail("key " + inQuotes(row) + " must be a row of " + std::to_string(cols) + " numbers, got " + describe(v[i]));
      }
      for (std::size_t k = 0; k < cols; ++k) m(i, k) = toNumber(v[i][k], row + "[" + std::to_string(k) + "]");
    }
    return m;
  }
  /// A vector of numbers (possibly empty).
  /// A vector of exactly n numbers.
  VecX vector(const std::string& key, int n) const {
    const json& v = required(key);
    if (!v.is_array() || static_cast<int>(v.size()) != n) {
      fail("key " + inQuotes(key) + " must be an array of " + std::to_string(n) + " numbers, got " + describe(v));
    }
    return vector(key);
  }
  VecX vector(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_array()) fail("key " + inQuotes(key) + " must be an array of numbers, got " + describe(v));
    VecX out(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) out[k] = toNumber(v[k], key + "[" + std::to_string(k) + "]");
    return out;
  }
  /// A direction (an axis) of exactly n numbers that can be normalised (directionProblem,
  /// core/magnitude_checks.hpp), as given (not normalised).
  VecX direction(const std::string& key, int n) const {
    VecX v = vector(key, n);
    const std::string problem = directionProblem(v);
    if (!problem.empty()) fail("key " + inQuotes(key) + " " + problem);
    return v;
  }
  /// A non-negative integer from an arbitrary JSON value (array entries).
  int index(const json& v, const std::string& label) const {
    if (!v.is_number_integer() || v.get<long>() < 0) {
      fail("key " + inQuotes(label) + " must be a non-negative integer, got " + describe(v));
    }
    return static_cast<int>(v.get<long>());
  }

  const json& object(const std::string& key) const {
    const json& v = required(key);
    if (!v.is_object()) fail("key " + inQuotes(key) + " must be an object {...}, got " + describe(v));
    return v;
  }

  /// The array under a required `key`.
  const json& requiredArray(const std::string& key) const {
    required(key);
    return array(key);
  }
  /// The array under `key`, or an empty one if the key is absent.
  const json& array(const std::string& key) const {
    static const json kEmpty = json::array();
    if (!has(key)) return kEmpty;
    const json& v = required(key);
    if (!v.is_array()) fail("key " + inQuotes(key) + " must be an array [...], got " + describe(v));
    return v;
  }

  double checkPositive(double x, const std::string& key) const {
    if (!(x > 0.0)) fail("key " + inQuotes(key) + " must be > 0, got " + fmt(x));
    checkNotTiny(x, key);
    return x;
  }
  double checkNonNegative(double x, const std::string& key) const {
    if (!(x >= 0.0)) fail("key " + inQuotes(key) + " must be >= 0, got " + fmt(x));
    if (x > 0.0) checkNotTiny(x, key);
    return x;
  }

 private:
  /// A positive magnitude below kMinPositiveMagnitude (core/magnitude_checks.hpp) is refused.
  void checkNotTiny(double x, const std::string& key) const {
    if (x < kMinPositiveMagnitude) {
      fail("key " + inQuotes(key) + " must be at least 1e-100 when it is not 0 (smaller values underflow or give "
           "infinite reciprocals in the products the engine forms), got " + fmt(x));
    }
  }
  double toNumber(const json& v, const std::string& label) const {
    if (!v.is_number()) fail("key " + inQuotes(label) + " must be a number, got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail("key " + inQuotes(label) + " must be a finite number, got " + fmt(x));
    if (std::fabs(x) > kMaxInputMagnitude) {
      fail("key " + inQuotes(label) + " must be at most 1e100 in magnitude (larger values overflow to inf in the "
           "products the engine forms), got " + fmt(x));
    }
    return x;
  }
  Vec2 toVec2(const json& v, const std::string& label) const {
    if (!v.is_array() || v.size() != 2) {
      fail("key " + inQuotes(label) + " must be an array of 2 numbers [x, y], got " + describe(v));
    }
    return Vec2(toNumber(v[0], label + "[0]"), toNumber(v[1], label + "[1]"));
  }

  const json& j_;
  std::string where_;
};

/// Runs a System / law-factory call and puts the scene location in front of its
/// InputError messages (keeping the exception type).
template <class F>
auto located(const std::string& where, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const ModelError& e) {
    throw ModelError(where + ": " + e.what());
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
}

/// Checks the "type" key against the allowed values and returns it.
inline std::string readType(const ObjectReader& r, const std::string& kind,
                     const std::vector<std::string>& types) {
  const std::string type = r.string("type");
  if (std::find(types.begin(), types.end(), type) == types.end()) {
    r.fail("unknown " + kind + " type " + inQuotes(type) + " (expected one of: " + join(types) + ")");
  }
  return type;
}

// ----- which command a scene file is for ----------------------------------------------------

/// The three scene formats, told apart by their top-level keys: a tensegrity scene has
/// "model": "tensegrity"; only multibody scenes have "bodies", "joints", "drivers",
/// "forces", "outputs"; only kinematics scenes have "links", "inputs", "analysis".
enum class SceneKind { Multibody, Kinematics, Tensegrity, Unknown };

struct SceneKindGuess {
  SceneKind kind = SceneKind::Unknown;
  std::string key;  ///< the key that tells: "\"analysis\"", "\"model\": \"tensegrity\""
};

inline SceneKindGuess guessSceneKind(const json& j) {
  if (!j.is_object()) return {};
  if (const auto it = j.find("model"); it != j.end() && it->is_string() && it->get<std::string>() == "tensegrity") {
    return {SceneKind::Tensegrity, "\"model\": \"tensegrity\""};
  }
  std::string multibody, kinematics;  // the first such key in the file's (sorted) order
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (multibody.empty() && (k == "bodies" || k == "joints" || k == "drivers" || k == "forces" || k == "outputs")) {
      multibody = k;
    }
    if (kinematics.empty() && (k == "links" || k == "inputs" || k == "analysis")) kinematics = k;
  }
  if (!multibody.empty() && kinematics.empty()) return {SceneKind::Multibody, inQuotes(multibody)};
  if (!kinematics.empty() && multibody.empty()) return {SceneKind::Kinematics, inQuotes(kinematics)};
  return {};
}

/// Refuses a scene of another format than `expected` with a message saying which
/// command it is for: `four_bar.json is a kinematics scene (key "analysis"): run it with
/// "flexmbd kinematics"`. A file of no recognisable format is left to the reader.
inline void checkSceneKind(const json& j, SceneKind expected, const std::string& source) {
  const SceneKindGuess g = guessSceneKind(j);
  if (g.kind == SceneKind::Unknown || g.kind == expected) return;
  const char* kind = g.kind == SceneKind::Multibody ? "multibody" : g.kind == SceneKind::Kinematics ? "kinematics"
                                                                                                    : "tensegrity";
  const char* command = g.kind == SceneKind::Kinematics ? "flexmbd kinematics" : "flexmbd run";
  throw InputError(source + " is a " + kind + " scene (key " + g.key + "): run it with \"" + command + "\"");
}

/// A time-law object {"type": "constant_speed", "speed": ...} (docs/scene-format.md).
TimeLawPtr parseTimeLaw(const json& j, const std::string& where);

}  // namespace flexmbd::jsonread
