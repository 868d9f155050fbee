#include "joints/drivers.hpp"

namespace flexmbd {

BodyCoordinateDriver::BodyCoordinateDriver(std::string name, BodyIndex body, int coordinate,
                                           std::string coordinateName, TimeLawPtr law)
    : LawDriver<Constraint>(std::move(law), std::move(name), std::vector<BodyIndex>{body}),
      coordinate_(coordinate),
      coordinateName_(std::move(coordinateName)) {}

void BodyCoordinateDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                    ConstraintEvaluation& out) const {
  // local coordinates: only q_k (coordinatesUsed)
  out.h = VecX::Constant(1, bodies[0].q[coordinate_]);
  out.G = MatX::Ones(1, 1);
  if (withHessians) out.H = {MatX::Zero(1, 1)};
}

JointAngleDriver::JointAngleDriver(std::string name, BodyIndex bodyI, const Vec2& pointI,
                                   BodyIndex bodyJ, const Vec2& pointJ, TimeLawPtr law)
    : LawDriver<TwoPointConstraint>(std::move(law), std::move(name), bodyI, pointI, bodyJ, pointJ) {}

void JointAngleDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies, withHessians);
  out.h = VecX::Constant(1, p.phiJ - p.phiI);
  out.G = p.JphiJ - p.JphiI;
  if (withHessians) out.H = {p.HphiJ - p.HphiI};
}

JointDisplacementDriver::JointDisplacementDriver(std::string name, BodyIndex bodyI,
                                                 const Vec2& pointI, BodyIndex bodyJ,
                                                 const Vec2& pointJ, const Vec2& axis,
                                                 TimeLawPtr law)
    : LawDriver<TwoPointConstraint>(std::move(law), std::move(name), bodyI, pointI, bodyJ, pointJ) {
  if (!(axis.norm() > 1e-12)) throw InputError("driver '" + this->name() + "': axis must be non-zero");
  axis_ = axis.normalized();
}

void JointDisplacementDriver::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                                       ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies, withHessians);
  double s = 0.0;
  RowVecX grad;
  MatX hess;
  projectOnRotatingAxis(p, axis_, withHessians, s, grad, &hess);
  out.h = VecX::Constant(1, s);
  out.G = grad;
  if (withHessians) out.H = {hess};
}

}  // namespace flexmbd
