#include "joints/fixed_joint.hpp"

namespace flexmbd {

FixedJoint::FixedJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                       const Vec2& pointJ, double referenceAngle)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ),
      referenceAngle_(referenceAngle) {
  requireFinite(referenceAngle, "joint '" + this->name() + "': reference angle");
}

void FixedJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  // h = (r_j - r_i, phi_j - phi_i - phi0) (Haug1989)
  const PointPair& p = pair(bodies, withHessians, out.work);
  out.h.resize(3);
  out.h << p.d, p.phiJ - p.phiI - referenceAngle_;
  out.G.resize(3, p.n());
  out.G.topRows(2) = p.D;
  out.G.row(2) = p.JphiJ - p.JphiI;
  if (!withHessians) return;
  out.H.resize(3);
  out.H[0] = p.Hdx;
  out.H[1] = p.Hdy;
  out.H[2] = p.HphiJ - p.HphiI;
}

VecX FixedJoint::reactions(const BodyStates&, const VecX& lambda) const {
  return Eigen::Vector3d(-lambda[0], -lambda[1], -lambda[2]);
}

}  // namespace flexmbd
