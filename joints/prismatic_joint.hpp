/// @file
/// Prismatic joint: point j slides along an axis fixed in body i; relative rotation locked.
#pragma once

#include "joints/point_pair.hpp"

namespace flexmbd {

/// h1 = n_w^T (r_j - r_i) = 0 with n_w = A(phi_i) S a the normal of the sliding axis a
/// (body-i frame); h2 = phi_j - phi_i - phi0 = 0 (phi0: relative angle when assembled;
/// Haug1989).
class PrismaticJoint final : public TwoPointConstraint {
 public:
  /// @throws InputError if the axis is zero or not finite.
  PrismaticJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                 const Vec2& pointJ, const Vec2& axis, double referenceAngle);
  int numEquations() const override { return 2; }
  std::string typeName() const override { return "prismatic"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  std::vector<std::string> reactionNames() const override { return {"fx", "fy", "m"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;
  /// Unit sliding axis in the frame of body i.
  const Vec2& axis() const { return axis_; }

 private:
  Vec2 axis_;
  double referenceAngle_;
};

}  // namespace flexmbd
