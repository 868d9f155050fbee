#include "joints/world_frames.hpp"

#include <cmath>

#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/errors.hpp"
#include "core/ground.hpp"
#include "core/magnitude_checks.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

BodyPose spatialBodyPose(const Body& body, const ConstVecRef& q, const std::string& who) {
  BodyPose pose;
  if (dynamic_cast<const Ground*>(&body)) return pose;
  if (!dynamic_cast<const RigidBody3d*>(&body) && !dynamic_cast<const FfrBody3d*>(&body)) {
    throw InputError(who + ": body '" + body.name() +
                     "' has no spatial frame (expected a spatial rigid or flexible body, or the ground)");
  }
  // both spatial bodies: q = (R (3), p (4), ...), r = R + A(p) u (rigid_body_3d.hpp, ffr_body_3d.hpp)
  pose.position = q.head<3>();
  pose.orientation = quaternionRotation(q.segment<4>(3));
  return pose;
}

Mat3 frameAxesFromZ(const Vec3& zIn, const Vec3* xHint, const std::string& who) {
  const Vec3 z = unitDirection(zIn, who + ": axis");
  Vec3 x;
  if (xHint) {
    const Vec3 hint = unitDirection(*xHint, who + ": x_axis");
    x = hint - z.dot(hint) * z;  // Gram-Schmidt (GolubVanLoan2013): the part of the hint normal to z
    if (!(x.norm() > 1e-9)) {
      throw InputError(who + ": x_axis must not be parallel to axis (expected a direction across the axis)");
    }
    x.normalize();
  } else {
    Eigen::Index k = 0;
    z.cwiseAbs().minCoeff(&k);  // the world axis least aligned with z
    x = (Vec3::Unit(k) - z[k] * z).normalized();
  }
  Mat3 C;
  C.col(0) = x;
  C.col(1) = z.cross(x);
  C.col(2) = z;
  return C;
}

JointFrame worldJointFrame(const Vec3& point, const Vec3& axis, const Vec3* xHint, const std::string& who) {
  if (!point.allFinite()) throw InputError(who + ": point must be a finite vector");
  JointFrame f;
  f.point = point;
  f.axes = frameAxesFromZ(axis, xHint, who);
  return f;
}

JointFrame bodyFrameFromWorld(const Body& body, const JointFrame& world, const std::string& who) {
  const BodyPose pose = spatialBodyPose(body, body.initialCoordinates(), who);
  JointFrame f;
  // r = R + A u  =>  u = A^T (r - R); world axes C = A C_body  =>  C_body = A^T C (Nikravesh1988)
  f.point = pose.orientation.transpose() * (world.point - pose.position);
  f.axes = pose.orientation.transpose() * world.axes;
  body.resolvePoint(f.point, who);  // a flexible body: the point must be a node (throws naming `who`)
  return f;
}

std::array<JointFrame, 2> jointFramesFromWorld(const System& sys, BodyIndex bi, BodyIndex bj,
                                               const JointFrame& world, const std::string& who) {
  checkJointFrame(world, who + " (world frame)");
  return {bodyFrameFromWorld(sys.body(bi), world, who), bodyFrameFromWorld(sys.body(bj), world, who)};
}

}  // namespace flexmbd
