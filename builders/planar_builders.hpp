/// @file
/// Convenience builders of planar models (the C++ API most users need): free functions
/// that make a concrete body, joint, driver or force and add it to a System through its
/// generic addBody / addConstraint / addForce. Kept out of core/ so that the core does not
/// depend on the concrete bodies, joints and forces.
#pragma once

#include <string>

#include "bodies/rigid_body_2d.hpp"
#include "core/system.hpp"
#include "core/time_law.hpp"
#include "core/user_function.hpp"
#include "core/types.hpp"

namespace flexmbd {

BodyIndex addRigidBody(System& sys, const std::string& name, const RigidBodyProperties& props,
                       const FrameState2d& initial);
ConstraintIndex addRevoluteJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                 BodyIndex bodyJ, const Vec2& pointJ);
/// The relative rotation is locked at its value in the initial positions.
ConstraintIndex addPrismaticJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                  BodyIndex bodyJ, const Vec2& pointJ, const Vec2& axis);
/// The relative rotation is locked at its value in the initial positions.
ConstraintIndex addFixedJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                              BodyIndex bodyJ, const Vec2& pointJ);
/// Prescribes coordinate `coordinate` ("x", "y", "theta", ...) of a body.
ConstraintIndex addBodyCoordinateDriver(System& sys, const std::string& name, BodyIndex body,
                                        const std::string& coordinate, TimeLawPtr law);
/// Prescribes a revolute joint's relative angle or a prismatic joint's displacement
/// (planar, or spatial: addJointAngleDriver / addJointDisplacementDriver of
/// builders/spatial_builders.hpp).
ConstraintIndex addJointDriver(System& sys, const std::string& name, ConstraintIndex joint, TimeLawPtr law);
/// law: a user law f(t, l, l') in place of k (l - l0) + c l' (core/user_function.hpp).
ForceIndex addSpringDamper(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                           BodyIndex bodyJ, const Vec2& pointJ, double stiffness, double damping,
                           double freeLength, SpringLawPtr law = nullptr);
/// Acts on a revolute joint's relative angle; freeAngle: angle of zero torque (a spatial
/// revolute or cylindrical joint: addSpatialRotationalSpringDamper). law: a user law
/// tau(t, phi, phi') in place of k (phi - phi0) + c phi'.
ForceIndex addRotationalSpringDamper(System& sys, const std::string& name, ConstraintIndex revoluteJoint,
                                     double stiffness, double damping, double freeAngle, SpringLawPtr law = nullptr);
ForceIndex addAppliedLoad(System& sys, const std::string& name, BodyIndex body, const Vec2& point,
                          TimeLawPtr forceX, TimeLawPtr forceY, TimeLawPtr torque);

}  // namespace flexmbd
