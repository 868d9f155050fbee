/// @file
/// Prescribed force (world components) at a body point and torque on the body.
#pragma once

#include "core/force.hpp"
#include "core/time_law.hpp"

namespace flexmbd {

/// A load applied to one body (the planar and the spatial applied load): the ground does
/// not move, so a load on it would be accepted and do nothing.
/// @throws InputError "<who>: a load on the ground does nothing ..." if `body` is the ground.
void requireLoadableBody(BodyIndex body, const std::string& who);

/// Q = Jr^T F(t) + Jphi^T tau(t) at the given body point (virtual work, Haug1989); absent
/// laws count as zero.
class AppliedLoad final : public Force {
 public:
  AppliedLoad(std::string name, BodyIndex body, const Vec2& point, TimeLawPtr forceX,
              TimeLawPtr forceY, TimeLawPtr torque);
  std::string typeName() const override { return "applied_load"; }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  bool isConservative() const override { return false; }
  std::vector<Attachment> attachments() const override { return {{bodies()[0], lift(point_)}}; }

 private:
  Vec2 point_;
  TimeLawPtr forceX_, forceY_, torque_;
};

}  // namespace flexmbd
