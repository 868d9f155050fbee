/// @file
/// What a multibody system looks like at a state: every body as points, poly-lines and
/// polygons with the quantities drawn on them, and every joint as a point (and axis). One
/// place for the geometry that the VTK frames (results/vtk_writer.hpp) and the browser viewer
/// (viewer/html_viewer.hpp) draw.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bodies/body_geometry.hpp"
#include "core/system.hpp"

namespace flexmbd {

/// One drawing of the system. The topology (cells, their bodies, the joints) is the same
/// at every state of one SystemDrawer; only positions and point quantities change.
struct Drawing {
  enum class CellKind { PolyLine, Polygon };
  std::vector<Vec3> points;                ///< world axes
  std::vector<std::vector<int>> cells;     ///< indices into points
  std::vector<CellKind> cellKinds;         ///< per cell
  std::vector<int> cellBody;               ///< per cell: its entry in bodyNames
  std::vector<std::string> bodyNames;      ///< the bodies drawn, in order of appearance
  /// Per point: "elastic_displacement" (world axes; zero on rigid bodies), "section_force"
  /// (N, Qy, Qz) and "section_moment" (Mx, My, Mz) in element axes of spatial beams.
  std::vector<std::pair<std::string, std::vector<Vec3>>> pointVectors;
  /// Per point: "axial_force" N, "bending_moment" (|M| of spatial beams), "von_mises" (Pa).
  std::vector<std::pair<std::string, std::vector<double>>> pointScalars;
  /// Joints: name, world position of their first attachment, and the world direction of
  /// their axis (revolute, prismatic and cylindrical spatial joints; planar revolute
  /// joints: z; zero where a joint has no axis).
  std::vector<std::string> jointNames;
  std::vector<Vec3> jointPoints, jointAxes;
};

/// Draws a finalized system at any state (see VtkWriter for what each body looks like).
class SystemDrawer {
 public:
  /// `geometry`: shapes drawn as surfaces on rigid bodies (Scene::geometry); `feBodies`:
  /// fe_bodies drawn as their deformed outer surface (Scene::feBodies). `inertiaBoxes`:
  /// a rigid body with no geometry is also drawn as the box of its inertia (spatial), or
  /// as the square plate of its inertia if its points coincide (planar: a slider) (the
  /// viewer; the VTK frames keep the triads and lines).
  SystemDrawer(const System& sys, int subdivisions = 4, const std::vector<BodyGeometry>& geometry = {},
               const std::vector<FeBodyDrawing>& feBodies = {}, bool inertiaBoxes = false);
  /// The drawing at coordinates q (System order).
  Drawing draw(const VecX& q) const;
  /// Bodies with nothing to draw (a flexible_invariants body without attachment points).
  const std::vector<std::string>& bodiesNotDrawn() const { return notDrawn_; }

 private:
  void drawBody(int b, const ConstVecRef& q, Drawing& d) const;
  void drawJoints(const VecX& q, Drawing& d) const;

  const System& sys_;
  int subdivisions_;
  std::vector<std::string> notDrawn_;
  std::vector<std::vector<Vec2>> rigidPoints_;  // per planar body: body-frame points of its line
  // per spatial body: its joint points (body frame), drawn as lines from the centre of
  // mass, and the length of the axis triad drawn at the centre of mass
  std::vector<std::vector<Vec3>> spatialPoints_;
  double triad_ = 0.1;
  std::vector<std::vector<SurfaceMesh>> surfaces_;  // per body: its geometry, body axes
  std::vector<FeBodyDrawing> feBodies_;
  std::vector<int> feIndex_;  // per body: its entry in feBodies_, or -1
};

/// The box whose inertia about its centre equals the principal moments (Ix, Iy, Iz) of a
/// body of mass m: side a_x^2 = 6 (Iy + Iz - Ix) / m, and so on (Ix = m (a_y^2 + a_z^2) / 12:
/// MeriamKraige, table D/4);
/// a side that would be imaginary or below 1e-3 of the longest is set to that.
Vec3 inertiaBoxSides(double mass, const Vec3& principalMoments);

}  // namespace flexmbd
