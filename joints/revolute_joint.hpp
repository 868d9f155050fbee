/// @file
/// Revolute joint: point i of body i and point j of body j coincide.
#pragma once

#include "joints/point_pair.hpp"

namespace flexmbd {

/// h = r_j - r_i = 0 (2 equations; Haug1989).
class RevoluteJoint final : public TwoPointConstraint {
 public:
  using TwoPointConstraint::TwoPointConstraint;
  int numEquations() const override { return 2; }
  std::string typeName() const override { return "revolute"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  std::vector<std::string> reactionNames() const override { return {"fx", "fy", "m"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;
};

}  // namespace flexmbd
