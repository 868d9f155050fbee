#include "joints/prismatic_joint.hpp"

#include "core/errors.hpp"

namespace flexmbd {

PrismaticJoint::PrismaticJoint(std::string name, BodyIndex bodyI, const Vec2& pointI,
                               BodyIndex bodyJ, const Vec2& pointJ, const Vec2& axis,
                               double referenceAngle)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ),
      referenceAngle_(referenceAngle) {
  const std::string who = "joint '" + this->name() + "'";
  requireFinite(axis.x(), who + ": axis[0]");
  requireFinite(axis.y(), who + ": axis[1]");
  requireFinite(referenceAngle, who + ": reference angle");
  if (axis.norm() < 1e-12) throw InputError(who + ": axis must be a non-zero vector, got [0, 0]");
  axis_ = axis.normalized();
}

void PrismaticJoint::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                              ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies, withHessians);
  double s = 0.0;
  RowVecX grad;
  MatX hess;
  projectOnRotatingAxis(p, perp(axis_), withHessians, s, grad, &hess);
  out.h.resize(2);
  out.h << s, p.phiJ - p.phiI - referenceAngle_;
  out.G.resize(2, p.n());
  out.G.row(0) = grad;
  out.G.row(1) = p.JphiJ - p.JphiI;
  if (withHessians) out.H = {hess, p.HphiJ - p.HphiI};
}

VecX PrismaticJoint::reactions(const std::vector<BodyState>& bodies, const VecX& lambda) const {
  const double phiI = bodies[0].point(pointI(), false).phi;
  const Vec2 n = rotation(phiI) * perp(axis_);
  const Vec2 f = -lambda[0] * n;
  return Eigen::Vector3d(f.x(), f.y(), -lambda[1]);
}

}  // namespace flexmbd
