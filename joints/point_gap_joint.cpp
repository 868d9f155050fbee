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

std::vector<FrameEquation> gapsAlong(const std::vector<int>& axes) {
  std::vector<FrameEquation> gaps;
  for (const int a : axes) gaps.push_back({FrameEquation::AxisGap, a, 0});
  return gaps;
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
      gaps_(gapsAlong(axes)) {}

void PointGapJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  evaluateFrameEquations(bodies, frameI_, frameJ_, gaps_, withHessians, out);
}

VecX PointGapJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  KinematicsWork work;
  const FramePair pair(bodies, frameI_, frameJ_, false, work);
  Vec3 f = Vec3::Zero();  // -G^T lambda over body j's translation
  for (int e = 0; e < numEquations(); ++e) f -= lambda[e] * pair.axisI(gaps_[e].a);
  return f;
}

}  // namespace flexmbd
