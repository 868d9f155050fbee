/// @file
/// Point-in-plane joint (spatial): a point of body j stays in a plane fixed in body i;
/// it moves freely in the plane and the bodies rotate freely.
#pragma once

#include "core/system.hpp"
#include "joints/point_gap_joint.hpp"

namespace flexmbd {

/// h = z_i^T (r_j - r_i) = 0, with z_i the plane's normal (body-i axes) through point i
/// (Haug1989, ch. 9, the planar joint's gap equation). One equation.
class PointInPlaneJoint final : public PointGapJoint {
 public:
  /// @throws InputError if a point or the normal is not finite or the normal is zero.
  PointInPlaneJoint(std::string name, BodyIndex bodyI, const Vec3& pointI, BodyIndex bodyJ, const Vec3& pointJ,
                    const Vec3& normal)
      : PointGapJoint(std::move(name), bodyI, pointI, normal, "normal", bodyJ, pointJ, {2}) {}
  std::string typeName() const override { return "point_in_plane"; }
};

/// pointJ of bodyJ in the plane through pointI of bodyI with `normal` (body-i axes).
ConstraintIndex addPointInPlaneJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec3& pointI,
                                     BodyIndex bodyJ, const Vec3& pointJ, const Vec3& normal);

struct ComponentKind;
/// The scene kind "point_in_plane" of "joints" (builders/component_kinds.cpp lists it).
ComponentKind pointInPlaneJointKind();

}  // namespace flexmbd
