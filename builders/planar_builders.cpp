#include "builders/planar_builders.hpp"

#include <memory>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "forces/applied_load.hpp"
#include "forces/rotational_spring_damper.hpp"
#include "forces/spring_damper.hpp"
#include "joints/drivers.hpp"
#include "joints/fixed_joint.hpp"
#include "joints/prismatic_joint.hpp"
#include "joints/revolute_joint.hpp"
#include "joints/spatial_joint.hpp"
#include "builders/spatial_builders.hpp"

namespace flexmbd {

namespace {

// The message of System::addConstraint / addForce for a body index out of range, given
// before the builder reads the body.
void checkBody(const System& sys, BodyIndex i, const std::string& user) {
  if (i.value < 0 || i.value >= sys.numBodies()) {
    throw InputError(user + ": body index " + std::to_string(i.value) + " does not exist");
  }
}

double initialRelativeAngle(const System& sys, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                            const Vec2& pointJ) {
  const VecX qi = sys.body(bodyI).initialCoordinates();
  const VecX qj = sys.body(bodyJ).initialCoordinates();
  return sys.body(bodyJ).pointKinematics(qj, pointJ, false).phi -
         sys.body(bodyI).pointKinematics(qi, pointI, false).phi;
}

}  // namespace

BodyIndex addRigidBody(System& sys, const std::string& name, const RigidBodyProperties& props,
                       const FrameState2d& initial) {
  return sys.addBody(std::make_unique<RigidBody2d>(name, props, initial));
}

ConstraintIndex addRevoluteJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                 BodyIndex bodyJ, const Vec2& pointJ) {
  checkBody(sys, bodyI, "joint '" + name + "'");
  checkBody(sys, bodyJ, "joint '" + name + "'");
  return sys.addConstraint(std::make_unique<RevoluteJoint>(name, bodyI, pointI, bodyJ, pointJ));
}

ConstraintIndex addPrismaticJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                  BodyIndex bodyJ, const Vec2& pointJ, const Vec2& axis) {
  checkBody(sys, bodyI, "joint '" + name + "'");
  checkBody(sys, bodyJ, "joint '" + name + "'");
  const double phi0 = initialRelativeAngle(sys, bodyI, pointI, bodyJ, pointJ);
  return sys.addConstraint(std::make_unique<PrismaticJoint>(name, bodyI, pointI, bodyJ, pointJ, axis, phi0));
}

ConstraintIndex addFixedJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                              BodyIndex bodyJ, const Vec2& pointJ) {
  checkBody(sys, bodyI, "joint '" + name + "'");
  checkBody(sys, bodyJ, "joint '" + name + "'");
  const double phi0 = initialRelativeAngle(sys, bodyI, pointI, bodyJ, pointJ);
  return sys.addConstraint(std::make_unique<FixedJoint>(name, bodyI, pointI, bodyJ, pointJ, phi0));
}

ConstraintIndex addBodyCoordinateDriver(System& sys, const std::string& name, BodyIndex b,
                                        const std::string& coordinate, TimeLawPtr law) {
  checkBody(sys, b, "driver '" + name + "'");
  const Body& body = sys.body(b);
  const auto names = body.coordinateNames();
  for (int k = 0; k < static_cast<int>(names.size()); ++k) {
    if (names[k] == coordinate) {
      if (body.coordinatesOfVelocities({k}) != std::vector<int>{k}) {
        throw InputError("driver '" + name + "': coordinate '" + coordinate + "' of body '" + body.name() +
                         "' is a rotation parameter; drive a joint angle instead");
      }
      return sys.addConstraint(std::make_unique<BodyCoordinateDriver>(name, b, k, coordinate, std::move(law)));
    }
  }
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InputError("driver '" + name + "': body '" + body.name() + "' has no coordinate '" + coordinate +
                   "' (it has: " + (known.empty() ? "none" : known) + ")");
}

ConstraintIndex addJointDriver(System& sys, const std::string& name, ConstraintIndex joint, TimeLawPtr law) {
  if (joint.value < 0 || joint.value >= sys.numConstraints()) {
    throw InputError("driver '" + name + "': joint index does not exist");
  }
  const Constraint& c = sys.constraint(joint);
  if (const auto* s = dynamic_cast<const SpatialJoint*>(&c)) {  // spatial: builders/spatial_builders.hpp
    if (s->type() == SpatialJointType::Revolute) return addJointAngleDriver(sys, name, joint, std::move(law));
    if (s->type() == SpatialJointType::Prismatic) return addJointDisplacementDriver(sys, name, joint, std::move(law));
    throw InputError("driver '" + name + "': joint '" + c.name() + "' is a spatial " + c.typeName() +
                     " joint; addJointDriver drives revolute (angle) and prismatic (displacement) joints, "
                     "addJointAngleDriver / addJointDisplacementDriver choose for a cylindrical one");
  }
  if (const auto* r = dynamic_cast<const RevoluteJoint*>(&c)) {
    return sys.addConstraint(std::make_unique<JointAngleDriver>(name, r->bodies()[0], r->pointI(), r->bodies()[1],
                                                                r->pointJ(), std::move(law)));
  }
  if (const auto* p = dynamic_cast<const PrismaticJoint*>(&c)) {
    return sys.addConstraint(std::make_unique<JointDisplacementDriver>(
        name, p->bodies()[0], p->pointI(), p->bodies()[1], p->pointJ(), p->axis(), std::move(law)));
  }
  throw InputError("driver '" + name + "': joint '" + c.name() + "' is a " + c.typeName() +
                   " joint; expected a revolute (angle) or prismatic (displacement) joint");
}

ForceIndex addSpringDamper(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                           BodyIndex bodyJ, const Vec2& pointJ, double stiffness, double damping,
                           double freeLength, SpringLawPtr law) {
  checkBody(sys, bodyI, "force '" + name + "'");
  checkBody(sys, bodyJ, "force '" + name + "'");
  return sys.addForce(std::make_unique<SpringDamper>(name, bodyI, pointI, bodyJ, pointJ, stiffness, damping, freeLength,
                                                     std::move(law)));
}

ForceIndex addRotationalSpringDamper(System& sys, const std::string& name, ConstraintIndex joint,
                                     double stiffness, double damping, double freeAngle, SpringLawPtr law) {
  if (joint.value < 0 || joint.value >= sys.numConstraints()) {
    throw InputError("force '" + name + "': joint index does not exist");
  }
  if (dynamic_cast<const SpatialJoint*>(&sys.constraint(joint))) {  // spatial revolute or cylindrical
    return addSpatialRotationalSpringDamper(sys, name, joint, stiffness, damping, freeAngle, std::move(law));
  }
  const auto* r = dynamic_cast<const RevoluteJoint*>(&sys.constraint(joint));
  if (!r) {
    throw InputError("force '" + name + "': joint '" + sys.constraint(joint).name() +
                     "' is not a revolute joint; a rotational spring-damper needs one");
  }
  return sys.addForce(std::make_unique<RotationalSpringDamper>(name, r->bodies()[0], r->pointI(), r->bodies()[1],
                                                               r->pointJ(), stiffness, damping, freeAngle,
                                                               std::move(law)));
}

ForceIndex addAppliedLoad(System& sys, const std::string& name, BodyIndex b, const Vec2& point,
                          TimeLawPtr forceX, TimeLawPtr forceY, TimeLawPtr torque) {
  checkBody(sys, b, "force '" + name + "'");
  return sys.addForce(
      std::make_unique<AppliedLoad>(name, b, point, std::move(forceX), std::move(forceY), std::move(torque)));
}

}  // namespace flexmbd
