#include "joints/point_gap_joint.hpp"

#include "joints/world_frames.hpp"

namespace flexmbd {

namespace {

JointFrame frameAlong(const Vec3& point, const Vec3& z, const std::string& who) {
  JointFrame f;
  f.point = point;
  f.axes = frameAxesFromZ(z, nullptr, who);
  return f;
}

JointFrame frameAt(const Vec3& point) {
  JointFrame f;
  f.point = point;
  return f;
}

}  // namespace

PointGapJoint::PointGapJoint(std::string name, BodyIndex bodyI, const Vec3& pointI, const Vec3& z,
                             const std::string& zName, BodyIndex bodyJ, const Vec3& pointJ, std::vector<int> axes)
    : FramePairConstraint(name, bodyI, frameAlong(pointI, z, "joint '" + name + "': " + zName), bodyJ,
                          frameAt(pointJ), "joint"),
      axes_(std::move(axes)) {}

void PointGapJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  FramePair pair(bodies, frameI_, frameJ_, withHessians, out.work);
  const int m = numEquations(), n = pair.numVelocities(), nq = pair.numCoordinates();
  out.h.resize(m);
  out.G.resize(m, n);
  if (withHessians) out.H.resize(m);
  for (int e = 0; e < m; ++e) {
    MatX* H = withHessians ? &out.H[e] : nullptr;
    if (H) H->setZero(n, nq);
    pair.axisGap(axes_[e], out.h[e], out.G.row(e), H);
  }
}

VecX PointGapJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  KinematicsWork work;
  const FramePair pair(bodies, frameI_, frameJ_, false, work);
  Vec3 f = Vec3::Zero();  // -G^T lambda over body j's translation
  for (int e = 0; e < numEquations(); ++e) f -= lambda[e] * pair.axisI(axes_[e]);
  return f;
}

}  // namespace flexmbd
