/// @file
/// Drivers: rheonomic constraints h(q) - f(t) = 0 that prescribe a motion in time (driving
/// constraints, Haug1989).
#pragma once

#include "core/errors.hpp"
#include "core/time_law.hpp"
#include "core/user_function.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

/// What every driver shares, on top of the constraint type Base that gives h(q):
/// one equation, the prescribed f(t) from a time law, and its effort -lambda (the
/// generalised force applied along the driven quantity) as the reaction output.
template <class Base>
class LawDriver : public Base {
 public:
  template <class... Args>
  explicit LawDriver(TimeLawPtr law, Args&&... args) : Base(std::forward<Args>(args)...), law_(std::move(law)) {
    if (!law_) throw InputError("driver '" + this->name() + "': a time law is required");
  }
  int numEquations() const override { return 1; }
  bool isDriver() const override { return true; }
  void timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const override {
    LawValue v;
    try {
      v = law_->evaluate(t);
    } catch (const UserFunctionError& e) {  // a user law raised: name the driver
      rethrowWithOwner(e, "driver '" + this->name() + "'");
    }
    f.setConstant(1, v.f);
    df.setConstant(1, v.df);
    ddf.setConstant(1, v.ddf);
  }
  std::vector<std::string> reactionNames() const override { return {"effort"}; }
  VecX reactions(const BodyStates&, const VecX& lambda) const override {
    return VecX::Constant(1, -lambda[0]);
  }

 private:
  TimeLawPtr law_;
};

/// Prescribes coordinate k of one body (e.g. a frame angle theta or position x):
/// h = q_k, f = law(t) (Haug1989).
class BodyCoordinateDriver final : public LawDriver<Constraint> {
 public:
  BodyCoordinateDriver(std::string name, BodyIndex body, int coordinate, std::string coordinateName,
                       TimeLawPtr law);
  std::string typeName() const override { return "body_" + coordinateName_; }
  std::optional<std::vector<int>> coordinatesUsed(int) const override { return std::vector<int>{coordinate_}; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;

 private:
  int coordinate_;
  std::string coordinateName_;
};

/// Prescribes the relative angle phi_j - phi_i of a revolute joint's two points:
/// h = phi_j - phi_i, f = law(t) (Haug1989).
class JointAngleDriver final : public LawDriver<TwoPointConstraint> {
 public:
  JointAngleDriver(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                   const Vec2& pointJ, TimeLawPtr law);
  std::string typeName() const override { return "joint_angle"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
};

/// Prescribes the displacement of a prismatic joint: s = a_w^T (r_j - r_i), with a_w the
/// sliding axis carried by body i; f = law(t) (Haug1989).
class JointDisplacementDriver final : public LawDriver<TwoPointConstraint> {
 public:
  JointDisplacementDriver(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                          const Vec2& pointJ, const Vec2& axis, TimeLawPtr law);
  std::string typeName() const override { return "joint_displacement"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;

 private:
  Vec2 axis_;
};

}  // namespace flexmbd
