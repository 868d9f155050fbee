/// @file
/// Readers of the objects of spatial scenes ("dimension": 3): rigid bodies with
/// orientations, joints as frame pairs, their drivers and the spatial force elements
/// (docs/scene-format.md, "Spatial scenes"). Called by scene/scene.cpp.
#pragma once

#include <array>
#include <functional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "bodies/body_geometry.hpp"
#include "bodies/shape_inertia.hpp"
#include "core/system.hpp"
#include "scene/json_reader.hpp"

namespace flexmbd::scenereaders {

/// A body / a joint (not a driver) by name. @throws InputError listing the known ones.
BodyIndex lookupBody(const System& sys, const std::string& name, const jsonread::ObjectReader& r);
ConstraintIndex lookupJoint(const System& sys, const std::string& name, const jsonread::ObjectReader& r);
/// The two different bodies of key "bodies" ["I", "J"]; `what` names the element in the
/// message ("a joint connects two different bodies").
std::array<BodyIndex, 2> lookupBodyPair(const System& sys, const jsonread::ObjectReader& r, const std::string& what);

/// Keys "stiffness", "damping" (default 0) and "free_length" of a spring-damper, the
/// free length by default `initialLength()` (the points' distance in the initial positions).
struct SpringDamperLaw {
  double stiffness = 0.0, damping = 0.0, freeLength = 0.0;
};
SpringDamperLaw readSpringDamperLaw(const jsonread::ObjectReader& r, const std::function<double()>& initialLength);

/// A rotation from an "orientation" object: {"quaternion": [e0, e1, e2, e3]} (normalised),
/// {"axis": [x, y, z], "angle": a} (radians) or {"matrix": [[...], [...], [...]]} (rows;
/// orthonormal, determinant +1). Exactly one form.
Mat3 parseOrientation(const nlohmann::json& j, const std::string& where);

/// A body object; `baseDir`: the folder the files of an "fe_body" are relative to; an
/// fe_body's drawing (surface, stress shapes) goes to `drawings` if given.
void parseSpatialBody(const nlohmann::json& j, const std::string& where, System& sys, const std::string& baseDir = "",
                      std::vector<FeBodyDrawing>* drawings = nullptr);
/// Key "geometry" of a rigid body (planar or spatial): one shape or an array of them,
/// placed in the body frame, for viewing only. @throws InputError starting with `where`.
std::vector<SolidShape> parseGeometry(const nlohmann::json& j, const std::string& where);
void parseSpatialJoint(const nlohmann::json& j, const std::string& where, System& sys);
void parseSpatialDriver(const nlohmann::json& j, const std::string& where, System& sys);
void parseSpatialForce(const nlohmann::json& j, const std::string& where, System& sys);

}  // namespace flexmbd::scenereaders
