/// @file
/// Fixed joint (weld): the points coincide and the relative angle stays at its reference.
#pragma once

#include "joints/point_pair.hpp"

namespace flexmbd {

/// h = [r_j - r_i; phi_j - phi_i - phi0] = 0 (3 equations; Haug1989); phi0 is the relative
/// angle of the assembled model (addFixedJoint of builders/planar_builders.hpp takes it
/// from the initial positions).
class FixedJoint final : public TwoPointConstraint {
 public:
  FixedJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
             const Vec2& pointJ, double referenceAngle);
  int numEquations() const override { return 3; }
  std::string typeName() const override { return "fixed"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  std::vector<std::string> reactionNames() const override { return {"fx", "fy", "m"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;

 private:
  double referenceAngle_;
};

}  // namespace flexmbd
