/// @file
/// Linear translational spring-damper between two body points.
#pragma once

#include "core/force.hpp"
#include "core/user_function.hpp"

namespace flexmbd {

/// Tension f = k (l - l0) + c ldot along e = d/l, d = r_j - r_i; generalised force
/// Q = -f D^T e (D = dd/dq; Haug1989); potential V = k (l - l0)^2 / 2. With a user law
/// (core/user_function.hpp), f = law(t, l, ldot) instead (k, c, l0 unused; no potential).
class SpringDamper final : public Force {
 public:
  /// @throws InputError if k < 0, c < 0, l0 < 0 or a value is not finite.
  SpringDamper(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
               const Vec2& pointJ, double stiffness, double damping, double freeLength,
               SpringLawPtr law = nullptr);
  std::string typeName() const override { return "spring_damper"; }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  double potentialEnergy(const BodyStates& bodies) const override;
  bool isConservative() const override { return damping_ == 0.0 && !law_; }
  bool dependsOnTime() const override { return law_ != nullptr; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], lift(pointI_)}, {bodies()[1], lift(pointJ_)}};
  }
  /// Current length (for outputs and tests).
  double length(const BodyStates& bodies) const;

 private:
  Vec2 pointI_, pointJ_;
  double stiffness_, damping_, freeLength_;
  SpringLawPtr law_;
};

}  // namespace flexmbd
