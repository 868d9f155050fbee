// The Python methods of the kinds declared through the registry
// (builders/component_kinds.hpp): System.add_<type>_<kind>(name=..., key=value, ...),
// one per kind, its docstring from the declaration, its keys checked and read by the
// scene reader itself (scene/component_reader.hpp), so Python and scene files give the
// same components and the same messages.
#include <nlohmann/json.hpp>

#include "bindings_support.hpp"
#include "builders/component_kinds.hpp"
#include "scene/component_reader.hpp"

namespace flexmbd::pybind {

namespace {

std::string methodName(const ComponentKind& k) {
  return "add_" + k.type + "_" + k.section.substr(0, k.section.size() - 1);
}

std::string docstring(const ComponentKind& k) {
  std::string d = k.summary + "\n\nKeyword arguments (the keys of the scene's \"" + k.type +
                  "\" object, docs/scene-format.md):\n  name: the name, unique in the system\n";
  for (const KeySpec& s : k.keys) {
    d += "  " + s.name + (s.unit.empty() ? "" : " [" + s.unit + "]") + ": " + s.description + "\n";
  }
  return d + "Bodies are given by name (\"ground\" for the ground); points and directions have 2 "
             "coordinates in a planar model, 3 in a spatial one. Returns the index of the new element.";
}

/// 2 or 3: the length of the first point or direction given (a planar or spatial model).
int dimensionOf(const ComponentKind& k, const nlohmann::json& keys) {
  for (const KeySpec& s : k.keys) {
    if (!keys.contains(s.name)) continue;
    const nlohmann::json& v = keys[s.name];
    if (s.type == KeyType::Direction && v.is_array()) return v.size() == 3 ? 3 : 2;
    if (s.type == KeyType::PointPair && v.is_array() && !v.empty() && v[0].is_array()) return v[0].size() == 3 ? 3 : 2;
  }
  return k.dimensions == KindDimensions::Spatial ? 3 : 2;
}

}  // namespace

void bindComponentKinds(py::class_<System>& system) {
  for (const ComponentKind& kind : componentKinds()) {  // a static list: the captured reference lives on
    const std::string method = methodName(kind);
    system.def(
        method.c_str(),
        [&kind, method](System& sys, const py::kwargs& keys) {
          const std::string text = py::module_::import("json").attr("dumps")(keys).cast<std::string>();
          const nlohmann::json j = nlohmann::json::parse(text);
          scenereaders::addComponent(sys, dimensionOf(kind, j), kind.section, kind.type, j, method);
          return sys.findConstraint(j.value("name", std::string()));
        },
        docstring(kind).c_str());
  }
}

}  // namespace flexmbd::pybind
