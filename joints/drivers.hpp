// Drivers: rheonomic constraints h(q) - f(t) = 0 that prescribe a motion in time.
#pragma once

#include "core/time_law.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

/// Prescribes coordinate k of one body (e.g. a frame angle theta or position x):
/// h = q_k, f = law(t).
class BodyCoordinateDriver final : public Constraint {
 public:
  BodyCoordinateDriver(std::string name, BodyIndex body, int coordinate, std::string coordinateName,
                       TimeLawPtr law);
  int numEquations() const override { return 1; }
  std::string typeName() const override { return "body_" + coordinateName_; }
  bool isDriver() const override { return true; }
  void evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                ConstraintEvaluation& out) const override;
  void timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const override;
  std::vector<std::string> reactionNames() const override { return {"effort"}; }
  VecX reactions(const std::vector<BodyState>& bodies, const VecX& lambda) const override;

 private:
  int coordinate_;
  std::string coordinateName_;
  TimeLawPtr law_;
};

/// Prescribes the relative angle phi_j - phi_i of a revolute joint's two points:
/// h = phi_j - phi_i, f = law(t).
class JointAngleDriver final : public TwoPointConstraint {
 public:
  JointAngleDriver(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                   const Vec2& pointJ, TimeLawPtr law);
  int numEquations() const override { return 1; }
  std::string typeName() const override { return "joint_angle"; }
  bool isDriver() const override { return true; }
  void evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                ConstraintEvaluation& out) const override;
  void timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const override;
  std::vector<std::string> reactionNames() const override { return {"effort"}; }
  VecX reactions(const std::vector<BodyState>& bodies, const VecX& lambda) const override;

 private:
  TimeLawPtr law_;
};

/// Prescribes the displacement of a prismatic joint: s = a_w^T (r_j - r_i), with a_w the
/// sliding axis carried by body i; f = law(t).
class JointDisplacementDriver final : public TwoPointConstraint {
 public:
  JointDisplacementDriver(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                          const Vec2& pointJ, const Vec2& axis, TimeLawPtr law);
  int numEquations() const override { return 1; }
  std::string typeName() const override { return "joint_displacement"; }
  bool isDriver() const override { return true; }
  void evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                ConstraintEvaluation& out) const override;
  void timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const override;
  std::vector<std::string> reactionNames() const override { return {"effort"}; }
  VecX reactions(const std::vector<BodyState>& bodies, const VecX& lambda) const override;

 private:
  Vec2 axis_;
  TimeLawPtr law_;
};

}  // namespace flexmbd
