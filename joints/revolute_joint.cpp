#include "joints/revolute_joint.hpp"

namespace flexmbd {

void RevoluteJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  // h = r_j - r_i (Haug1989)
  const PointPair& p = pair(bodies, withHessians, out.work);
  out.h = p.d;
  out.G = p.D;
  if (!withHessians) return;
  out.H.resize(2);
  out.H[0] = p.Hdx;
  out.H[1] = p.Hdy;
}

VecX RevoluteJoint::reactions(const BodyStates&, const VecX& lambda) const {
  // Constraint force on body j is -G_j^T lambda = force -lambda at point j (Haug1989).
  return Eigen::Vector3d(-lambda[0], -lambda[1], 0.0);
}

}  // namespace flexmbd
