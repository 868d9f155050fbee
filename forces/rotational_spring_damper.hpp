/// @file
/// Rotational spring-damper acting in a revolute joint.
#pragma once

#include "core/force.hpp"
#include "core/user_function.hpp"

namespace flexmbd {

/// Torque tau = k (phi - phi0) + c phidot on the relative angle phi = phi_j - phi_i of
/// the joint's two points; Q = -tau dphi/dq^T (Haug1989); potential V = k (phi - phi0)^2 / 2. With a
/// user law (core/user_function.hpp), tau = law(t, phi, phidot) instead (no potential).
class RotationalSpringDamper final : public Force {
 public:
  RotationalSpringDamper(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                         const Vec2& pointJ, double stiffness, double damping,
                         double freeAngle, SpringLawPtr law = nullptr);
  std::string typeName() const override { return "rotational_spring_damper"; }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  double potentialEnergy(const BodyStates& bodies) const override;
  bool isConservative() const override { return damping_ == 0.0 && !law_; }
  bool dependsOnTime() const override { return law_ != nullptr; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], lift(pointI_)}, {bodies()[1], lift(pointJ_)}};
  }

 private:
  Vec2 pointI_, pointJ_;
  double stiffness_, damping_, freeAngle_;
  SpringLawPtr law_;
};

}  // namespace flexmbd
