#include "joints/fixed_joint.hpp"

namespace flexmbd {

FixedJoint::FixedJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                       const Vec2& pointJ, double referenceAngle)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ),
      referenceAngle_(referenceAngle) {
  requireFinite(referenceAngle, "joint '" + this->name() + "': reference angle");
}

void FixedJoint::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                          ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies, withHessians);
  out.h.resize(3);
  out.h << p.d, p.phiJ - p.phiI - referenceAngle_;
  out.G.resize(3, p.n());
  out.G.topRows(2) = p.D;
  out.G.row(2) = p.JphiJ - p.JphiI;
  if (withHessians) out.H = {p.Hdx, p.Hdy, p.HphiJ - p.HphiI};
}

VecX FixedJoint::reactions(const std::vector<BodyState>&, const VecX& lambda) const {
  return Eigen::Vector3d(-lambda[0], -lambda[1], -lambda[2]);
}

}  // namespace flexmbd
