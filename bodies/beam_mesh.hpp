/// @file
/// Beam finite-element meshes of flexible bodies: nodes (body frame, undeformed) and
/// two-node elements, planar (BeamMesh2d) and spatial (BeamMesh3d).
#pragma once

#include <vector>

#include "core/types.hpp"
#include "elements/beam_section.hpp"

namespace flexmbd {

/// Most elements of one beam body (scenes, C++ and Python alike): every node of a nodal
/// body keeps a dense block of shapes as wide as the body's coordinates, so memory grows
/// with the square of the mesh (0.9 GB at 1,000 spatial elements; docs/stability.md,
/// "Sizes").
constexpr long kMaxElements = 1000;

/// Nodes (body frame, undeformed) and two-node beam elements.
struct BeamMesh2d {
  struct Element {
    int node1 = 0, node2 = 0;
    BeamSection section;
  };
  std::vector<Vec2> nodes;
  std::vector<Element> elements;
  /// A straight beam of `length` along the body x axis from `origin`, n equal elements.
  /// @throws InputError unless numElements >= 1 and length > 0.
  static BeamMesh2d straight(double length, int numElements, const BeamSection& section,
                             const Vec2& origin = Vec2::Zero());
};

/// Nodes (body frame, undeformed) and two-node spatial beam elements.
struct BeamMesh3d {
  struct Element {
    int node1 = 0, node2 = 0;
    BeamSection3d section;
    /// The element's y axis hint (body frame): made orthogonal to the element axis, it
    /// is the section's y axis (BeamElement3d).
    Vec3 yHint = Vec3::UnitY();
  };
  std::vector<Vec3> nodes;
  std::vector<Element> elements;
  /// A straight beam of `length` along the body x axis from `origin`, n equal elements,
  /// every element with the y axis hint `yHint`.
  /// @throws InputError unless numElements >= 1 and length > 0.
  static BeamMesh3d straight(double length, int numElements, const BeamSection3d& section,
                             const Vec3& origin = Vec3::Zero(), const Vec3& yHint = Vec3::UnitY());
};

}  // namespace flexmbd
