// Mass and inertia of a spatial rigid body from a solid shape of uniform density: box,
// solid cylinder, tube (hollow cylinder) and sphere, centred on the body frame origin (the
// centre of mass) with their edges / axis along body axes (docs/scene-format.md, "shape";
// docs/spatial.md, "Inertia from shapes").
#pragma once

#include "bodies/rigid_body_3d.hpp"

namespace flexmbd {

struct SolidShape {
  enum class Type { Box, Cylinder, Tube, Sphere };
  Type type = Type::Box;
  Vec3 size = Vec3::Ones();  ///< box: edge lengths along body x, y, z (m)
  double radius = 1.0;       ///< cylinder, sphere: radius; tube: outer radius (m)
  double innerRadius = 0.0;  ///< tube: inner radius, in [0, radius) (m)
  double length = 1.0;       ///< cylinder, tube: length along the axis (m)
  int axis = 2;              ///< cylinder, tube: the body axis (0 = x, 1 = y, 2 = z) of the shape's axis
};

/// The shape's volume (m^3). @throws InputError for non-positive or non-finite dimensions.
double shapeVolume(const SolidShape& s);

/// The principal moments of inertia (body axes, about the centre) of the shape of mass
/// `mass` (kg m^2). @throws InputError as shapeVolume, or for mass <= 0.
Mat3 shapeInertia(const SolidShape& s, double mass);

/// Mass and inertia of a body that is the shape: the mass `mass`, or density x volume if
/// `mass` is not given (pass density > 0 and mass = 0).
/// @throws InputError as shapeInertia.
RigidBody3dProperties shapeProperties(const SolidShape& s, double mass, double density);

}  // namespace flexmbd
