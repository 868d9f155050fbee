#include "joints/drivers.hpp"

#include "core/errors.hpp"

namespace flexmbd {
namespace {

void lawToVectors(const TimeLaw& law, double t, VecX& f, VecX& df, VecX& ddf) {
  const LawValue v = law.evaluate(t);
  f = VecX::Constant(1, v.f);
  df = VecX::Constant(1, v.df);
  ddf = VecX::Constant(1, v.ddf);
}

void requireLaw(const TimeLawPtr& law, const std::string& name) {
  if (!law) throw InputError("driver '" + name + "': a time law is required");
}

}  // namespace

BodyCoordinateDriver::BodyCoordinateDriver(std::string name, BodyIndex body, int coordinate,
                                           std::string coordinateName, TimeLawPtr law)
    : Constraint(std::move(name), {body}),
      coordinate_(coordinate),
      coordinateName_(std::move(coordinateName)),
      law_(std::move(law)) {
  requireLaw(law_, this->name());
}

void BodyCoordinateDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                    ConstraintEvaluation& out) const {
  const int n = bodies[0].body.numCoordinates();
  out.h = VecX::Constant(1, bodies[0].q[coordinate_]);
  out.G = MatX::Zero(1, n);
  out.G(0, coordinate_) = 1.0;
  if (withHessians) out.H = {MatX::Zero(n, n)};
}

void BodyCoordinateDriver::timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const {
  lawToVectors(*law_, t, f, df, ddf);
}

VecX BodyCoordinateDriver::reactions(const std::vector<BodyState>&, const VecX& lambda) const {
  return VecX::Constant(1, -lambda[0]);
}

JointAngleDriver::JointAngleDriver(std::string name, BodyIndex bodyI, const Vec2& pointI,
                                   BodyIndex bodyJ, const Vec2& pointJ, TimeLawPtr law)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ), law_(std::move(law)) {
  requireLaw(law_, this->name());
}

void JointAngleDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies);
  out.h = VecX::Constant(1, p.phiJ - p.phiI);
  out.G = p.JphiJ - p.JphiI;
  if (withHessians) out.H = {p.HphiJ - p.HphiI};
}

void JointAngleDriver::timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const {
  lawToVectors(*law_, t, f, df, ddf);
}

VecX JointAngleDriver::reactions(const std::vector<BodyState>&, const VecX& lambda) const {
  return VecX::Constant(1, -lambda[0]);
}

JointDisplacementDriver::JointDisplacementDriver(std::string name, BodyIndex bodyI,
                                                 const Vec2& pointI, BodyIndex bodyJ,
                                                 const Vec2& pointJ, const Vec2& axis,
                                                 TimeLawPtr law)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ), law_(std::move(law)) {
  requireLaw(law_, this->name());
  if (!(axis.norm() > 1e-12)) throw InputError("driver '" + this->name() + "': axis must be non-zero");
  axis_ = axis.normalized();
}

void JointDisplacementDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                       ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies);
  double s = 0.0;
  RowVecX grad;
  MatX hess;
  projectOnRotatingAxis(p, axis_, withHessians, s, grad, &hess);
  out.h = VecX::Constant(1, s);
  out.G = grad;
  if (withHessians) out.H = {hess};
}

void JointDisplacementDriver::timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const {
  lawToVectors(*law_, t, f, df, ddf);
}

VecX JointDisplacementDriver::reactions(const std::vector<BodyState>&, const VecX& lambda) const {
  return VecX::Constant(1, -lambda[0]);
}

}  // namespace flexmbd
