/// @file
/// Scene objects of the kinds declared through the registry (builders/component_kinds.hpp):
/// their keys validated against the declaration (unknown, missing, of the wrong shape or
/// not a body of the model: an InputError naming the object and the key), then built; and the
/// reference of their keys that docs/scene-format.md holds (generated, kept current by
/// a test).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/component_kind.hpp"
#include "scene/json_reader.hpp"

namespace flexmbd::scenereaders {

/// The types of `section` ("joints") that a scene of `dimension` (2 or 3) takes from the registry.
std::vector<std::string> registeredTypes(const std::string& section, int dimension);

/// If the object's "type" is a declared kind of `section`: reads and builds it and
/// returns true; false for any other type (the caller's own kinds).
/// @throws InputError for a kind of the other dimension, and for any key at fault.
bool readRegisteredComponent(const std::string& section, int dimension, const jsonread::ObjectReader& r,
                             System& sys);

/// A joint_angle or joint_displacement driver (`driverType`) of a joint of a declared
/// kind: the joint makes it (Constraint::makeDriver), from the object's "law"; returns
/// false for a joint of any other kind (the caller's own rules).
/// @throws InputError if the joint has no such motion to drive.
bool readDriverOfRegisteredJoint(const std::string& driverType, const std::string& name, ConstraintIndex joint,
                                 const jsonread::ObjectReader& r, System& sys);

/// Builds a component of a declared kind from its keys as a JSON object (the Python
/// module's `add_<type>_<kind>` methods: the same checks and messages as a scene's).
/// `where` names the object in messages. @throws InputError.
void addComponent(System& sys, int dimension, const std::string& section, const std::string& type,
                  const nlohmann::json& keys, const std::string& where);

/// The Markdown reference of every declared kind: per kind a heading, its summary and a
/// table of its keys (type, unit, description).
std::string componentReference();

/// The markers around the generated reference in docs/scene-format.md.
inline constexpr const char* kReferenceBegin = "<!-- generated from the component declarations: begin -->";
inline constexpr const char* kReferenceEnd = "<!-- generated from the component declarations: end -->";

}  // namespace flexmbd::scenereaders
