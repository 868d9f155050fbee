/// @file
/// Point-on-line joint: a point of body j stays on a line fixed in body i, planar and
/// spatial; the point moves freely along the line and the bodies rotate freely. A
/// joint_displacement driver prescribes the point's position along the line.
#pragma once

#include "core/system.hpp"
#include "joints/point_gap_joint.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

/// Planar: h = n_w^T (r_j - r_i) = 0, n_w = A(phi_i) S a the normal of the line's
/// direction a (body-i axes) through point i (Haug1989, ch. 3, the translational
/// joint's first equation). One equation.
class PointOnLineJoint final : public TwoPointConstraint {
 public:
  /// @throws InputError if the direction is zero or not finite.
  PointOnLineJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ, const Vec2& pointJ,
                   const Vec2& direction);
  int numEquations() const override { return 1; }
  std::string typeName() const override { return "point_on_line"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  /// The force on body j at its point (world axes): normal to the line, no moment.
  std::vector<std::string> reactionNames() const override { return {"fx", "fy"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;
  /// "displacement": s = a_w^T (r_j - r_i) = law(t), the point's position along the line.
  std::unique_ptr<Constraint> makeDriver(const std::string& quantity, std::string name,
                                         TimeLawPtr law) const override;
  const Vec2& direction() const { return direction_; }

 private:
  Vec2 direction_;
};

/// Spatial: h = (x_i^T d, y_i^T d) = 0 with d = r_j - r_i and x_i, y_i normal to the
/// line's direction z_i (body-i axes) through point i (Haug1989, ch. 9, the cylindrical
/// joint's lateral equations). Two equations.
class PointOnLineJoint3d final : public PointGapJoint {
 public:
  /// @throws InputError if a point or the direction is not finite or the direction is zero.
  PointOnLineJoint3d(std::string name, BodyIndex bodyI, const Vec3& pointI, BodyIndex bodyJ, const Vec3& pointJ,
                     const Vec3& direction)
      : PointGapJoint(std::move(name), bodyI, pointI, direction, "direction", bodyJ, pointJ, {0, 1}) {}
  std::string typeName() const override { return "point_on_line"; }
  /// "displacement": s = z_i^T (r_j - r_i) = law(t), the point's position along the line.
  std::unique_ptr<Constraint> makeDriver(const std::string& quantity, std::string name,
                                         TimeLawPtr law) const override;
};

/// A planar point-on-line joint: pointJ of bodyJ on the line through pointI of bodyI
/// along `direction` (body-i axes).
ConstraintIndex addPointOnLineJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                    BodyIndex bodyJ, const Vec2& pointJ, const Vec2& direction);
/// The spatial one.
ConstraintIndex addPointOnLineJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec3& pointI,
                                    BodyIndex bodyJ, const Vec3& pointJ, const Vec3& direction);

struct ComponentKind;
/// The scene kind "point_on_line" of "joints" (builders/component_kinds.cpp lists it).
ComponentKind pointOnLineJointKind();

}  // namespace flexmbd
