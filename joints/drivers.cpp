#include "joints/drivers.hpp"

#include "core/magnitude_checks.hpp"

namespace flexmbd {

BodyCoordinateDriver::BodyCoordinateDriver(std::string name, BodyIndex body, int coordinate,
                                           std::string coordinateName, TimeLawPtr law)
    : LawDriver<Constraint>(std::move(law), std::move(name), std::vector<BodyIndex>{body}),
      coordinate_(coordinate),
      coordinateName_(std::move(coordinateName)) {}

void BodyCoordinateDriver::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  // local coordinates: only q_k (coordinatesUsed); h = q_k
  out.h.setConstant(1, bodies[0].q[coordinate_]);
  out.G.setOnes(1, 1);
  if (!withHessians) return;
  out.H.resize(1);
  out.H[0].setZero(1, 1);
}

JointAngleDriver::JointAngleDriver(std::string name, BodyIndex bodyI, const Vec2& pointI,
                                   BodyIndex bodyJ, const Vec2& pointJ, TimeLawPtr law)
    : LawDriver<TwoPointConstraint>(std::move(law), std::move(name), bodyI, pointI, bodyJ, pointJ) {}

void JointAngleDriver::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  // h = phi_j - phi_i (Haug1989)
  const PointPair& p = pair(bodies, withHessians, out.work);
  out.h.setConstant(1, p.phiJ - p.phiI);
  out.G = p.JphiJ - p.JphiI;
  if (!withHessians) return;
  out.H.resize(1);
  out.H[0] = p.HphiJ - p.HphiI;
}

JointDisplacementDriver::JointDisplacementDriver(std::string name, BodyIndex bodyI,
                                                 const Vec2& pointI, BodyIndex bodyJ,
                                                 const Vec2& pointJ, const Vec2& axis,
                                                 TimeLawPtr law)
    : LawDriver<TwoPointConstraint>(std::move(law), std::move(name), bodyI, pointI, bodyJ, pointJ) {
  axis_ = unitDirection(axis, "driver '" + this->name() + "': axis");
}

void JointDisplacementDriver::evaluate(const BodyStates& bodies, bool withHessians,
                                       ConstraintEvaluation& out) const {
  // h = a_w^T (r_j - r_i) (Haug1989)
  const PointPair& p = pair(bodies, withHessians, out.work);
  double s = 0.0;
  out.H.resize(1);
  projectOnRotatingAxis(p, axis_, s, out.work.row, withHessians ? &out.H[0] : nullptr, out.work.row2);
  out.h.setConstant(1, s);
  out.G = out.work.row;
}

}  // namespace flexmbd
