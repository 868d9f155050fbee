#include "scene/scene_path.hpp"

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

using nlohmann::json;

constexpr const char* kExpected = "expected a scene key such as 'solver.t_end' or 'bodies[1].mass'";

[[noreturn]] void badPath(const std::string& path, const std::string& what, const char* role = "scene path") {
  throw InputError(std::string(role) + " '" + path + "': " + what);
}

/// The integer between '[' and ']', or the error naming it.
long parseIndex(const std::string& path, const std::string& text, const char* role) {
  std::size_t used = 0;
  long k = 0;
  try {
    k = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size()) badPath(path, "[" + text + "] is not an index (" + kExpected + ")", role);
  return k;
}

/// The text of the path up to and including part `k` (for messages).
std::string prefix(const std::vector<ScenePathPart>& parts, std::size_t k) {
  std::string s;
  for (std::size_t i = 0; i <= k; ++i) {
    if (parts[i].isIndex) {
      s += "[" + std::to_string(parts[i].index) + "]";
    } else {
      s += (i ? "." : "") + parts[i].key;
    }
  }
  return s;
}

/// The value at `path`, which must exist and be a number.
template <class Json>
Json& numberAt(Json& root, const std::string& path) {
  const std::vector<ScenePathPart> parts = parseScenePath(path);
  Json* node = &root;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const ScenePathPart& p = parts[k];
    if (p.isIndex) {
      const long n = node->is_array() ? static_cast<long>(node->size()) : 0;
      if (!node->is_array() || p.index < -n || p.index >= n) {
        badPath(path, "no element [" + std::to_string(p.index) + "] at '" + prefix(parts, k) + "'" +
                          (node->is_array() ? " (the list has " + std::to_string(n) + " elements)" : " (not a list)"));
      }
      node = &(*node)[static_cast<std::size_t>(p.index < 0 ? p.index + n : p.index)];
    } else {
      if (!node->is_object()) badPath(path, "'" + prefix(parts, k) + "': its parent is not an object");
      const auto it = node->find(p.key);
      if (it == node->end()) badPath(path, "no key '" + p.key + "' at '" + prefix(parts, k) + "'");
      node = &*it;
    }
  }
  if (!node->is_number()) {
    badPath(path, "expected a number there, got " + std::string(node->type_name()) + " " + node->dump().substr(0, 60));
  }
  return *node;
}

}  // namespace

std::vector<ScenePathPart> parseScenePath(const std::string& path, const char* role) {
  if (path.empty()) badPath(path, std::string("the key is empty (") + kExpected + ")", role);
  std::vector<ScenePathPart> parts;
  std::size_t start = 0;
  while (true) {  // one piece between dots: name[k][k]...
    const std::size_t dot = path.find('.', start);
    std::string piece = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (piece.empty()) badPath(path, std::string("an empty name between dots (") + kExpected + ")", role);
    std::size_t open = piece.find('[');
    const std::string name = piece.substr(0, open);
    if (name.find(']') != std::string::npos) badPath(path, std::string("']' without its '[' (") + kExpected + ")", role);
    if (!name.empty()) parts.push_back({false, name, 0});
    while (open != std::string::npos) {
      const std::size_t close = piece.find(']', open);
      if (close == std::string::npos) badPath(path, std::string("'[' without its ']' (") + kExpected + ")", role);
      parts.push_back({true, "", parseIndex(path, piece.substr(open + 1, close - open - 1), role)});
      const std::size_t next = close + 1;
      if (next < piece.size() && piece[next] != '[') {
        badPath(path, "text after ']' that is not another [index] (" + std::string(kExpected) + ")", role);
      }
      open = next < piece.size() ? next : std::string::npos;
    }
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

double sceneNumber(const json& scene, const std::string& path) { return numberAt(scene, path).template get<double>(); }

void setSceneNumber(json& scene, const std::string& path, double value) { numberAt(scene, path) = value; }

}  // namespace flexmbd
