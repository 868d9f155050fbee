#include "joints/revolute_joint.hpp"

namespace flexmbd {

void RevoluteJoint::evaluate(const std::vector<BodyState>& bodies, bool withHessians,
                             ConstraintEvaluation& out) const {
  const PointPair p = pair(bodies, withHessians);
  out.h = p.d;
  out.G = p.D;
  if (withHessians) out.H = {p.Hdx, p.Hdy};
}

VecX RevoluteJoint::reactions(const std::vector<BodyState>&, const VecX& lambda) const {
  // Constraint force on body j is -G_j^T lambda = force -lambda at point j.
  return Eigen::Vector3d(-lambda[0], -lambda[1], 0.0);
}

}  // namespace flexmbd
