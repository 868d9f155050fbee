#include "builders/spatial_builders.hpp"

#include <cmath>
#include <utility>

#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"
#include "core/magnitude_checks.hpp"
#include "core/rotation_3d.hpp"
#include "forces/spatial_forces.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/world_frames.hpp"

namespace flexmbd {

namespace {

/// Body index in range and a body with a spatial frame (the ground, a spatial rigid or
/// flexible body): the message names `who`.
void checkSpatialBody(const System& sys, BodyIndex i, const std::string& who) {
  if (i.value < 0 || i.value >= sys.numBodies()) {
    throw InputError(who + ": body index " + std::to_string(i.value) + " does not exist");
  }
  const Body& b = sys.body(i);
  spatialBodyPose(b, b.initialCoordinates(), who);  // throws for a planar body
}

/// The spatial joint of index `joint` (its frames carry the drivers and springs).
const SpatialJoint& spatialJointAt(const System& sys, ConstraintIndex joint, const std::string& who) {
  if (joint.value < 0 || joint.value >= sys.numConstraints()) {
    throw InputError(who + ": joint index " + std::to_string(joint.value) + " does not exist");
  }
  const auto* j = dynamic_cast<const SpatialJoint*>(&sys.constraint(joint));
  if (!j) {
    throw InputError(who + ": joint '" + sys.constraint(joint).name() + "' is not a spatial joint (a " +
                     sys.constraint(joint).typeName() + ")");
  }
  return *j;
}

void requireJointType(const SpatialJoint& j, SpatialJointType a, SpatialJointType b, const std::string& who,
                      const std::string& what) {
  if (j.type() != a && j.type() != b) {
    throw InputError(who + ": " + what + " needs a " + toString(a) + " or " + toString(b) + " joint, but joint '" +
                     j.name() + "' is " + j.typeName());
  }
}

bool needsAxis(SpatialJointType t) { return t != SpatialJointType::Spherical && t != SpatialJointType::Fixed; }

}  // namespace

Mat3 rotationFromAxisAngle(const Vec3& axis, double angle) {
  const Vec3 unit = unitDirection(axis, "axis-angle rotation: axis");
  if (!std::isfinite(angle)) throw InputError("axis-angle rotation: angle must be finite");
  return quaternionRotation(quaternionFromAxisAngle(unit, angle));
}

Mat3 rotationFromQuaternion(const Vec4& quaternion) {
  if (!quaternion.allFinite() || !(quaternion.norm() > 0.0)) {
    throw InputError("quaternion rotation: the Euler parameters must be finite and not all zero");
  }
  return quaternionRotation(quaternion);  // normalises
}

JointFrame jointFrameFromAxis(const Vec3& point, const Vec3& axis) {
  if (!point.allFinite()) throw InputError("joint frame: point must be a finite vector");
  JointFrame f;
  f.point = point;
  f.axes = frameAxesFromZ(axis, nullptr, "joint frame");
  return f;
}

BodyIndex addRigidBody3d(System& sys, const std::string& name, const RigidBody3dProperties& props,
                         const FrameState3d& initial) {
  return sys.addBody(std::make_unique<RigidBody3d>(name, props, initial));
}

BodyIndex addFlexibleBody3d(System& sys, const std::string& name, std::shared_ptr<const FfrBeamModel3d> model,
                            const FrameState3d& initial, const VecX& qf0, const VecX& qf0dot) {
  return sys.addBody(std::make_unique<FfrBody3d>(name, std::move(model), initial, qf0, qf0dot));
}

BodyIndex addFlexibleBody3d(System& sys, const std::string& name, FfrInvariants3d invariants,
                            const FrameState3d& initial, const VecX& qf0, const VecX& qf0dot) {
  return sys.addBody(std::make_unique<FfrBody3d>(name, std::move(invariants), initial, qf0, qf0dot));
}

SpatialJointType spatialJointTypeFromString(const std::string& type) {
  static const SpatialJointType all[] = {SpatialJointType::Spherical,   SpatialJointType::Revolute,
                                         SpatialJointType::Prismatic,   SpatialJointType::Cylindrical,
                                         SpatialJointType::Universal,   SpatialJointType::Fixed,
                                         SpatialJointType::Planar};
  std::string known;
  for (SpatialJointType t : all) {
    if (type == toString(t)) return t;
    known += (known.empty() ? "" : ", ") + std::string(toString(t));
  }
  throw InputError("unknown spatial joint type '" + type + "' (expected one of: " + known + ")");
}

ConstraintIndex addSpatialJoint(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                const JointFrame& fi, BodyIndex bj, const JointFrame& fj) {
  const std::string who = "joint '" + name + "'";
  checkSpatialBody(sys, bi, who);
  checkSpatialBody(sys, bj, who);
  return sys.addConstraint(std::make_unique<SpatialJoint>(name, type, bi, fi, bj, fj));
}

ConstraintIndex addSpatialJointAtWorld(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                       BodyIndex bj, const JointFrame& world) {
  const std::string who = "joint '" + name + "'";
  checkSpatialBody(sys, bi, who);
  checkSpatialBody(sys, bj, who);
  checkJointFrame(world, who + ": world frame");
  const auto [fi, fj] = jointFramesFromWorld(sys, bi, bj, world, who);
  return sys.addConstraint(std::make_unique<SpatialJoint>(name, type, bi, fi, bj, fj));
}

ConstraintIndex addSpatialJointAtWorld(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                       BodyIndex bj, const Vec3& point, const Vec3* axis, const Vec3* xAxis) {
  const std::string who = "joint '" + name + "'";
  if (!axis && needsAxis(type)) {
    throw InputError(who + ": a " + std::string(toString(type)) + " joint needs its axis (world axes)");
  }
  if (type == SpatialJointType::Universal && !xAxis) {
    throw InputError(who + ": a universal joint needs x_axis (the cross's pin on the first body, world axes)");
  }
  if (xAxis && !axis) throw InputError(who + ": x_axis needs axis");
  JointFrame world;
  if (axis) {
    world = worldJointFrame(point, *axis, xAxis, who);
  } else {
    if (!point.allFinite()) throw InputError(who + ": point must be a finite vector");
    world.point = point;  // spherical, fixed: the world axes
  }
  return addSpatialJointAtWorld(sys, name, type, bi, bj, world);
}

ConstraintIndex addJointAngleDriver(System& sys, const std::string& name, ConstraintIndex joint, TimeLawPtr law) {
  const std::string who = "driver '" + name + "'";
  const SpatialJoint& j = spatialJointAt(sys, joint, who);
  requireJointType(j, SpatialJointType::Revolute, SpatialJointType::Cylindrical, who, "a joint angle driver");
  return sys.addConstraint(std::make_unique<SpatialJointAngleDriver>(name, j.bodies()[0], j.frameI(), j.bodies()[1],
                                                                     j.frameJ(), std::move(law)));
}

ConstraintIndex addJointDisplacementDriver(System& sys, const std::string& name, ConstraintIndex joint,
                                           TimeLawPtr law) {
  const std::string who = "driver '" + name + "'";
  const SpatialJoint& j = spatialJointAt(sys, joint, who);
  requireJointType(j, SpatialJointType::Prismatic, SpatialJointType::Cylindrical, who, "a joint displacement driver");
  return sys.addConstraint(std::make_unique<SpatialJointDisplacementDriver>(name, j.bodies()[0], j.frameI(),
                                                                            j.bodies()[1], j.frameJ(), std::move(law)));
}

double initialJointAngle(const System& sys, ConstraintIndex joint) {
  const SpatialJoint& j = spatialJointAt(sys, joint, "initialJointAngle");
  const BodyIndex bi = j.bodies()[0], bj = j.bodies()[1];
  const VecX qi = sys.body(bi).initialCoordinates(), qj = sys.body(bj).initialCoordinates();
  BodyStates states;
  states.add(sys.body(bi), qi.data(), nullptr);
  states.add(sys.body(bj), qj.data(), nullptr);
  KinematicsWork w;
  double theta = 0.0;
  evaluateJointAngle(states, j.frameI(), j.frameJ(), w, theta, w.row7, nullptr);
  return theta;
}

ForceIndex addSpatialSpringDamper(System& sys, const std::string& name, BodyIndex bi, const Vec3& pointI,
                                  BodyIndex bj, const Vec3& pointJ, double stiffness, double damping,
                                  std::optional<double> freeLength, SpringLawPtr law) {
  const std::string who = "force '" + name + "'";
  checkSpatialBody(sys, bi, who);
  checkSpatialBody(sys, bj, who);
  double l0 = 0.0;
  if (freeLength) {
    l0 = *freeLength;
  } else {
    if (!pointI.allFinite() || !pointJ.allFinite()) throw InputError(who + ": points must be finite");
    l0 = (sys.body(bj).frameKinematics(sys.body(bj).initialCoordinates(), pointJ).r -
          sys.body(bi).frameKinematics(sys.body(bi).initialCoordinates(), pointI).r)
             .norm();
  }
  return sys.addForce(
      std::make_unique<SpatialSpringDamper>(name, bi, pointI, bj, pointJ, stiffness, damping, l0, std::move(law)));
}

ForceIndex addSpatialRotationalSpringDamper(System& sys, const std::string& name, ConstraintIndex joint,
                                            double stiffness, double damping, std::optional<double> freeAngle,
                                            SpringLawPtr law) {
  const std::string who = "force '" + name + "'";
  const SpatialJoint& j = spatialJointAt(sys, joint, who);
  requireJointType(j, SpatialJointType::Revolute, SpatialJointType::Cylindrical, who, "a rotational spring-damper");
  if (!(stiffness >= 0.0) || !(damping >= 0.0) || !std::isfinite(stiffness) || !std::isfinite(damping)) {
    throw InputError(who + ": stiffness and damping must be finite and >= 0");
  }
  const double a0 = freeAngle ? *freeAngle : initialJointAngle(sys, joint);
  if (!std::isfinite(a0)) throw InputError(who + ": free_angle must be finite");
  return sys.addForce(std::make_unique<SpatialRotationalSpringDamper>(name, j.bodies()[0], j.frameI(), j.bodies()[1],
                                                                      j.frameJ(), stiffness, damping, a0,
                                                                      std::move(law)));
}

ForceIndex addSpatialBushing(System& sys, const std::string& name, BodyIndex bi, const JointFrame& fi, BodyIndex bj,
                             const JointFrame& fj, const std::array<double, 6>& stiffness,
                             const std::array<double, 6>& damping) {
  const std::string who = "force '" + name + "'";
  checkSpatialBody(sys, bi, who);
  checkSpatialBody(sys, bj, who);
  for (int k = 0; k < 6; ++k) {
    if (!(stiffness[k] >= 0.0) || !std::isfinite(stiffness[k])) {
      throw InputError(who + ": stiffness[" + std::to_string(k) + "] must be finite and >= 0");
    }
    if (!(damping[k] >= 0.0) || !std::isfinite(damping[k])) {
      throw InputError(who + ": damping[" + std::to_string(k) + "] must be finite and >= 0");
    }
  }
  return sys.addForce(std::make_unique<SpatialBushing>(name, bi, fi, bj, fj, stiffness, damping));
}

ForceIndex addSpatialBushingAtWorld(System& sys, const std::string& name, BodyIndex bi, BodyIndex bj,
                                    const JointFrame& world, const std::array<double, 6>& stiffness,
                                    const std::array<double, 6>& damping) {
  const std::string who = "force '" + name + "'";
  checkSpatialBody(sys, bi, who);
  checkSpatialBody(sys, bj, who);
  checkJointFrame(world, who + ": world frame");
  const auto [fi, fj] = jointFramesFromWorld(sys, bi, bj, world, who);
  return addSpatialBushing(sys, name, bi, fi, bj, fj, stiffness, damping);
}

ForceIndex addSpatialAppliedLoad(System& sys, const std::string& name, BodyIndex body, const Vec3& point,
                                 const std::array<TimeLawPtr, 6>& laws) {
  checkSpatialBody(sys, body, "force '" + name + "'");
  return sys.addForce(std::make_unique<SpatialAppliedLoad>(name, body, point, laws));
}

}  // namespace flexmbd
