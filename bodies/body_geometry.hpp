// What a body looks like, for viewing only (scene key "geometry" of a rigid body): solid
// shapes placed in the body frame, drawn as surfaces in the VTK frames (and by viewers);
// they take no part in the dynamics. docs/scene-format.md, "Geometry".
#pragma once

#include <vector>

#include "bodies/shape_inertia.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// The shapes drawn for one body (its body frame: offsets and orientations of the shapes).
struct BodyGeometry {
  BodyIndex body;
  std::vector<SolidShape> shapes;
};

/// A closed surface of polygons (VTK_POLYGON order: counter-clockwise seen from outside).
struct SurfaceMesh {
  std::vector<Vec3> points;              ///< body axes (the shape's offset and orientation applied)
  std::vector<std::vector<int>> faces;   ///< indices into points
};

/// The surface of the shape: a box's 6 faces; a cylinder's or a tube's `segments` side
/// facets (and a tube's inner ones) with their end faces; a sphere of `segments` meridians
/// and segments / 2 bands. The points lie on the exact surface.
/// @throws InputError as shapeVolume, or for segments < 3.
SurfaceMesh surfaceMesh(const SolidShape& s, int segments = 24);

}  // namespace flexmbd
