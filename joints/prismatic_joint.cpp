#include "joints/prismatic_joint.hpp"

#include "core/errors.hpp"
#include "core/magnitude_checks.hpp"

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
  axis_ = unitDirection(axis, who + ": axis");
}

void PrismaticJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  // h = (a_w^T d, phi_j - phi_i - phi0) with a_w the normal to the sliding axis (Haug1989)
  const PointPair& p = pair(bodies, withHessians, out.work);
  double s = 0.0;
  out.H.resize(2);
  projectOnRotatingAxis(p, perp(axis_), s, out.work.row, withHessians ? &out.H[0] : nullptr, out.work.row2);
  out.h.resize(2);
  out.h << s, p.phiJ - p.phiI - referenceAngle_;
  out.G.resize(2, p.n());
  out.G.row(0) = out.work.row;
  out.G.row(1) = p.JphiJ - p.JphiI;
  if (withHessians) out.H[1] = p.HphiJ - p.HphiI;
}

VecX PrismaticJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  const double phiI = bodies[0].point(pointI(), bodies.pointId(0), false).phi;
  const Vec2 n = rotation(phiI) * perp(axis_);
  const Vec2 f = -lambda[0] * n;
  return Eigen::Vector3d(f.x(), f.y(), -lambda[1]);
}

}  // namespace flexmbd
