#include "joints/point_in_plane_joint.hpp"

#include "core/component_kind.hpp"
#include "core/errors.hpp"
#include "joints/world_frames.hpp"

namespace flexmbd {

namespace {

/// Frame i: the plane's point, z along its normal; frame j: the point.
JointFrame planeFrame(const Vec3& point, const Vec3& normal, const std::string& who) {
  JointFrame f;
  f.point = point;
  f.axes = frameAxesFromZ(normal, nullptr, who + ": normal");
  return f;
}

JointFrame pointFrame(const Vec3& point) {
  JointFrame f;
  f.point = point;
  return f;
}

}  // namespace

PointInPlaneJoint::PointInPlaneJoint(std::string name, BodyIndex bodyI, const Vec3& pointI, BodyIndex bodyJ,
                                     const Vec3& pointJ, const Vec3& normal)
    : FramePairConstraint(name, bodyI, planeFrame(pointI, normal, "joint '" + name + "'"), bodyJ,
                          pointFrame(pointJ)) {
  const std::string who = "joint '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  checkJointFrame(frameI_, who + " frame 0");
  checkJointFrame(frameJ_, who + " frame 1");
}

void PointInPlaneJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  FramePair pair(bodies, frameI_, frameJ_, withHessians, out.work);
  const int n = pair.numVelocities(), nq = pair.numCoordinates();
  out.h.resize(1);
  out.G.resize(1, n);
  MatX* H = nullptr;
  if (withHessians) {
    out.H.resize(1);
    out.H[0].setZero(n, nq);
    H = &out.H[0];
  }
  pair.axisGap(2, out.h[0], out.G.row(0), H);
}

VecX PointInPlaneJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  KinematicsWork work;
  const FramePair pair(bodies, frameI_, frameJ_, false, work);
  return -lambda[0] * pair.axisI(2);  // -G^T lambda over body j's translation
}

ConstraintIndex addPointInPlaneJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec3& pointI,
                                     BodyIndex bodyJ, const Vec3& pointJ, const Vec3& normal) {
  return sys.addConstraint(std::make_unique<PointInPlaneJoint>(name, bodyI, pointI, bodyJ, pointJ, normal));
}

ComponentKind pointInPlaneJointKind() {
  ComponentKind k;
  k.section = "joints";
  k.type = "point_in_plane";
  k.dimensions = KindDimensions::Spatial;
  k.summary = "A point of the second body stays in a plane fixed in the first; it moves freely in the plane and "
              "the bodies turn freely.";
  k.keys = {
      {"bodies", KeyType::BodyPair, "", "", "The body carrying the plane, then the body carrying the point."},
      {"points", KeyType::PointPair, "m", "",
       "A point of the plane in the first body's axes, then the point in the second body's axes."},
      {"normal", KeyType::Direction, "", "", "The plane's normal in the first body's axes."},
  };
  k.build = [](System& sys, const ComponentArgs& a) {
    const auto [bi, bj] = a.bodyPair("bodies");
    const auto p = a.pointPair("points");
    addPointInPlaneJoint(sys, a.name(), bi, p[0], bj, p[1], a.direction("normal"));
  };
  return k;
}

}  // namespace flexmbd
