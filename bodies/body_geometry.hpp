/// @file
/// What a body looks like, for viewing only (scene key "geometry" of a rigid body): solid
/// shapes placed in the body frame, drawn as surfaces in the VTK frames (and by viewers);
/// they take no part in the dynamics. docs/scene-format.md, "Geometry".
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

struct FeBodyData;

/// How a body imported from an FE code is drawn (scene "fe_body"): the outer surface of
/// its mesh over its nodes (node a is the body's attachment point a, so the surface
/// follows the deformation), and the nodes' stress shapes if the scene gave stress
/// samples (von Mises in the frames; docs/fe-import.md, "Stresses").
struct FeBodyDrawing {
  BodyIndex body;
  std::vector<int> nodeIds;  ///< the FE code's node numbers, in the body's point order
  SurfaceMesh surface;       ///< points: the nodes' undeformed positions (FE axes)
  MatX stressShapes;         ///< 6 N x nf: node a's (sxx, syy, szz, sxy, syz, szx) = rows 6 a .. 6 a + 5 times q_f; or empty
};

/// The outer surface of a solid mesh: the element faces (corner nodes only: quadrilaterals
/// of hexahedra, wedges and pyramids, triangles of tetrahedra, wedges and pyramids) that
/// belong to one element only, oriented outwards as the element orders its nodes
/// (Abaqus/CalculiX C3D4/6/8/10/15/20, Ansys Tet/Wedge/Pyramid/Hex), and the shells
/// (Abaqus S3, S3R, S4, S4R, S8R: corner nodes) as they are. Points: every node. Elements
/// of other types (beams, MASS, ROTARYI) are skipped.
SurfaceMesh outerSurface(const FeBodyData& data);

/// The surface of the shape: a box's 6 faces; a cylinder's or a tube's `segments` side
/// facets (and a tube's inner ones) with their end faces; a sphere of `segments` meridians
/// and segments / 2 bands. The points lie on the exact surface.
/// @throws InputError as shapeVolume, or for segments < 3.
SurfaceMesh surfaceMesh(const SolidShape& s, int segments = 24);

}  // namespace flexmbd
