/// @file
/// Scene values named by a dotted path, "bodies[1].section.area" or "solver.t_end": the
/// syntax the study overrides use (python/flexmbd/__init__.py, apply_overrides), here for
/// the parameters of a sensitivity run (docs/sensitivities.md).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace flexmbd {

/// One step of a dotted path: an object key, or a list index (negative: from the end).
struct ScenePathPart {
  bool isIndex = false;  ///< a list index [k] rather than a key
  std::string key;       ///< the key (isIndex false)
  long index = 0;        ///< the index (isIndex true)
};

/// The keys and indices of `path`: names separated by dots, each followed by any number of
/// [k] (k an integer, negative from the end). The one parser of the syntax: Python's
/// apply_overrides calls it too (role "override").
/// @throws InputError "<role> '<path>': <what>" (empty, an empty name between dots, '['
/// without ']', an index that is not an integer, text after ']').
std::vector<ScenePathPart> parseScenePath(const std::string& path, const char* role = "scene path");

/// The number at `path` in a scene's JSON. @throws InputError naming the path: the key or
/// element that does not exist, a value that is not a number (booleans are not numbers).
double sceneNumber(const nlohmann::json& scene, const std::string& path);

/// Sets the number at `path` (which must exist and hold a number) to `value`.
/// @throws InputError as sceneNumber.
void setSceneNumber(nlohmann::json& scene, const std::string& path, double value);

}  // namespace flexmbd
