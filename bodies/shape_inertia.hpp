/// @file
/// Mass and inertia of a spatial rigid body from solid shapes of uniform density: box,
/// solid cylinder, tube (hollow cylinder) and sphere, each placed in the body by an offset
/// and an orientation; several shapes add up by the parallel-axis theorem. The body frame
/// is the centre of mass, so the shapes' common centre of mass must be at the body origin
/// (docs/scene-format.md, "shape"; docs/spatial.md, "Inertia from shapes").
#pragma once

#include <vector>

#include "bodies/rigid_body_3d.hpp"

namespace flexmbd {

struct SolidShape {
  enum class Type { Box, Cylinder, Tube, Sphere };
  Type type = Type::Box;
  Vec3 size = Vec3::Ones();  ///< box: edge lengths along body x, y, z (m)
  double radius = 1.0;       ///< cylinder, sphere: radius; tube: outer radius (m)
  double innerRadius = 0.0;  ///< tube: inner radius, in [0, radius) (m)
  double length = 1.0;       ///< cylinder, tube: length along the axis (m)
  int axis = 2;              ///< cylinder, tube: the shape axis (0 = x, 1 = y, 2 = z) of its own axis
  Vec3 offset = Vec3::Zero();              ///< the shape's centre in body axes (m)
  Mat3 orientation = Mat3::Identity();     ///< the shape's axes in body axes (a rotation matrix)
};

/// One shape of a body with exactly one of its mass or its density (the other 0).
struct ShapePart {
  SolidShape shape;
  double mass = 0.0;     ///< kg, or 0 when the density is given
  double density = 0.0;  ///< kg/m^3, or 0 when the mass is given
};

/// Mass, centre of mass and inertia of several shapes together.
struct CompositeInertia {
  double mass = 0.0;
  Vec3 centreOfMass = Vec3::Zero();  ///< body axes (m)
  Mat3 inertia = Mat3::Zero();       ///< about the centre of mass, body axes (kg m^2)
};

/// How far the shapes' centre of mass may lie from the body origin, relative to their
/// extent (the largest |offset| + half-diagonal): a rounding of offsets typed to 7 digits.
inline constexpr double kShapeCentreTolerance = 1e-6;

/// The shape's volume (m^3). @throws InputError for non-positive or non-finite dimensions.
double shapeVolume(const SolidShape& s);

/// The inertia of the shape of mass `mass` about its own centre, in its own axes: the
/// principal moments (kg m^2; offset and orientation not applied).
/// @throws InputError as shapeVolume, or for mass <= 0.
Mat3 shapeInertia(const SolidShape& s, double mass);

/// Mass, centre of mass and inertia of the parts, each turned by its orientation and moved
/// by its offset. @throws InputError (naming the part by index) as shapeInertia, for no
/// parts, or for a part with both or neither of mass and density.
CompositeInertia compositeInertia(const std::vector<ShapePart>& parts);

/// The body made of the parts. @throws InputError as compositeInertia, or when their
/// centre of mass is off the body origin by more than kShapeCentreTolerance (the message
/// gives it, and the shift that puts it there).
RigidBody3dProperties shapeProperties(const std::vector<ShapePart>& parts);

/// Mass and inertia of a body that is the shape: the mass `mass`, or density x volume if
/// `mass` is not given (pass density > 0 and mass = 0).
/// @throws InputError as shapeInertia.
RigidBody3dProperties shapeProperties(const SolidShape& s, double mass, double density);

}  // namespace flexmbd
