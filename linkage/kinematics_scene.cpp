// Strict reader of kinematics scene files (docs/kinematics.md). Same conventions as
// scene/scene.cpp: unknown keys first, then types and ranges; one-line errors
// "<location>: <what is wrong>, got <what was found>".
#include "linkage/kinematics_scene.hpp"

#include "scene/json_reader.hpp"
#include "scene/scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

using nlohmann::json;

using namespace jsonread;

/// Objects of kinematics scenes carry their name in error locations.
class Reader : public ObjectReader {
 public:
  Reader(const json& j, std::string where) : ObjectReader(j, std::move(where)) { peekName(); }
};

void parseNode(const json& j, const std::string& at, Linkage2d& linkage) {
  Reader r(j, at);
  const std::string type = r.string("type");
  if (type == "slider") {
    r.allowOnly(scenekeys::kKinematicsSliderNode, " for a slider node");
  } else if (type == "fixed" || type == "free") {
    r.allowOnly(scenekeys::kKinematicsNode, " for a " + type + " node");
  } else {
    r.fail("key \"type\" must be \"fixed\", \"free\" or \"slider\", got " + inQuotes(type));
  }
  const std::string name = r.name("name");
  const Vec2 position = r.vec2("position");
  const Vec2 direction = type == "slider" ? r.vec2("direction") : Vec2::UnitX();
  located(r.where(), [&] {
    if (type == "fixed") {
      linkage.addFixedNode(name, position);
    } else if (type == "free") {
      linkage.addFreeNode(name, position);
    } else {
      linkage.addSliderNode(name, position, direction);
    }
  });
}

void parseLink(const json& j, const std::string& at, Linkage2d& linkage) {
  Reader r(j, at);
  r.allowOnly(scenekeys::kKinematicsLink);
  const std::string name = r.name("name");
  const json& nodes = r.required("nodes");
  if (!nodes.is_array() || nodes.size() != 2 || !nodes[0].is_string() || !nodes[1].is_string()) {
    r.fail("key \"nodes\" must be two node names [\"node1\", \"node2\"], got " + describe(nodes));
  }
  const double length = r.has("length") ? r.positive("length", 0.0) : 0.0;
  located(r.where(), [&] { linkage.addLink(name, nodes[0].get<std::string>(), nodes[1].get<std::string>(), length); });
}

void parseInput(const json& j, const std::string& at, Linkage2d& linkage) {
  Reader r(j, at);
  const std::string type = r.string("type");
  const std::string name = r.name("name");
  if (type == "link_angle") {
    r.allowOnly(scenekeys::kLinkAngleInput, " for a link_angle input");
    const std::string link = r.name("link");
    const std::string node = r.has("node") ? r.name("node") : "";
    const double ratio = r.number("ratio", 1.0);
    located(r.where(), [&] { linkage.addLinkAngleInput(name, link, node, ratio); });
  } else if (type == "slider_position" || type == "node_x" || type == "node_y") {
    r.allowOnly(scenekeys::kNodeInput, " for a " + type + " input");
    const std::string node = r.name("node");
    const double ratio = r.number("ratio", 1.0);
    located(r.where(), [&] {
      if (type == "slider_position") {
        linkage.addSliderInput(name, node, ratio);
      } else {
        linkage.addNodeCoordinateInput(name, node, type == "node_x" ? 0 : 1, ratio);
      }
    });
  } else {
    r.fail("key \"type\" must be \"link_angle\", \"slider_position\", \"node_x\" or \"node_y\", got " + inQuotes(type));
  }
}

KinematicSettings parseAnalysis(const json& j) {
  Reader r(j, "analysis");
  r.allowOnly(scenekeys::kAnalysis);
  KinematicSettings s;
  s.start = r.number("start", s.start);
  s.end = r.number("end", s.end);
  s.steps = static_cast<int>(r.integer("steps", s.steps, 1, kMaxKinematicSteps));
  s.speed = r.number("speed", s.speed);
  s.acceleration = r.number("acceleration", s.acceleration);
  s.tolerance = r.positive("tolerance", s.tolerance);
  s.maxIterations = static_cast<int>(r.integer("max_iterations", s.maxIterations, 1, 1000000));
  const std::string corrector = r.string("corrector", "newton");
  if (corrector == "newton") {
    s.corrector = CorrectorKind::Newton;
  } else if (corrector == "modified_newton") {
    s.corrector = CorrectorKind::ModifiedNewton;
  } else {
    r.fail("key \"corrector\" must be \"newton\" or \"modified_newton\", got " + inQuotes(corrector));
  }
  s.singularTolerance = r.positive("singular_tolerance", s.singularTolerance);
  s.locateTolerance = r.positive("locate_tolerance", s.locateTolerance);
  located("analysis", [&] { s.validate(); });
  return s;
}

/// Duplicate keys are errors (nlohmann would keep the last one silently).
class DuplicateKeyCheck {
 public:
  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys_.emplace_back();
    if (event == json::parse_event_t::object_end && !keys_.empty()) keys_.pop_back();
    if (event == json::parse_event_t::key && !keys_.empty()) {
      const std::string k = parsed.get<std::string>();
      if (!keys_.back().insert(k).second) throw InputError("duplicate key " + inQuotes(k) + " (each key may appear once)");
    }
    return true;
  }

 private:
  std::vector<std::set<std::string>> keys_;
};

}  // namespace

KinematicsScene parseKinematicsScene(const json& j) {
  Reader top(j, "top level");
  top.allowOnly(scenekeys::kKinematicsScene);
  KinematicsScene scene;
  scene.name = top.string("name", "");
  Linkage2d& linkage = scene.linkage;
  const json& nodes = top.requiredArray("nodes");
  if (nodes.empty()) top.fail("key \"nodes\" must list at least one node");
  for (std::size_t i = 0; i < nodes.size(); ++i) parseNode(nodes[i], "nodes[" + std::to_string(i) + "]", linkage);
  const json& links = top.requiredArray("links");
  if (links.empty()) top.fail("key \"links\" must list at least one link");
  for (std::size_t i = 0; i < links.size(); ++i) parseLink(links[i], "links[" + std::to_string(i) + "]", linkage);
  const json& inputs = top.requiredArray("inputs");
  for (std::size_t i = 0; i < inputs.size(); ++i) parseInput(inputs[i], "inputs[" + std::to_string(i) + "]", linkage);
  scene.settings = top.has("analysis") ? parseAnalysis(top.required("analysis")) : KinematicSettings{};
  try {  // the linkage's own messages may already start with "linkage: " (not said twice)
    linkage.finalize();
  } catch (const ModelError& e) {
    const std::string m = e.what();
    throw ModelError(m.rfind("linkage: ", 0) == 0 ? m : "linkage: " + m);
  } catch (const InputError& e) {
    const std::string m = e.what();
    throw InputError(m.rfind("linkage: ", 0) == 0 ? m : "linkage: " + m);
  }
  return scene;
}

KinematicsScene parseKinematicsSceneText(const std::string& text, const std::string& source) {
  checkJsonNesting(text, source);
  json j;
  try {
    j = json::parse(text, DuplicateKeyCheck{}, /*allow_exceptions=*/true);
  } catch (const json::parse_error& e) {
    throw InputError(source + ": invalid JSON at byte " + std::to_string(e.byte) + ": " + plainMessage(e));
  } catch (const json::out_of_range& e) {
    throw InputError(source + ": " + plainMessage(e) + " (the number is too large for a double; numbers must be finite)");
  } catch (const json::exception& e) {
    throw InputError(source + ": invalid JSON: " + plainMessage(e));
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  checkSceneKind(j, SceneKind::Kinematics, source);
  try {
    return parseKinematicsScene(j);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

KinematicsScene loadKinematicsScene(const std::string& path) {
  return parseKinematicsSceneText(jsonread::readSceneFile(path), path);
}

}  // namespace flexmbd
