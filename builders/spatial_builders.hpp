/// @file
/// Convenience builders of spatial models, the counterpart of builders/planar_builders.hpp:
/// free functions that make a spatial body, joint, driver or force and add it to a System
/// through its generic addBody / addConstraint / addForce (docs/spatial.md). What the
/// scene reader does for "dimension": 3 scenes, from C++:
///   BodyIndex arm = addRigidBody3d(sys, "arm", shapeProperties(box, 0.0, 7800.0), init);
///   ConstraintIndex hinge = addSpatialJointAtWorld(sys, "hinge", SpatialJointType::Revolute,
///                                                  kGround, arm, Vec3::Zero(), &axis);
///   addJointAngleDriver(sys, "motor", hinge, makeConstantSpeedLaw(2.0));
/// Bound in Python with the same names in snake case (docs/python.md).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/system.hpp"
#include "core/time_law.hpp"
#include "core/user_function.hpp"
#include "joints/frame_pair.hpp"
#include "joints/spatial_joint.hpp"

namespace flexmbd {

// ----- orientations and frames ------------------------------------------------------------

/// The rotation by `angle` (rad) about `axis` (normalised).
/// @throws InputError if the axis is zero or not finite, or the angle not finite.
Mat3 rotationFromAxisAngle(const Vec3& axis, double angle);
/// The rotation of the Euler parameters (e0, e1, e2, e3) (normalised).
/// @throws InputError if the quaternion is zero or not finite.
Mat3 rotationFromQuaternion(const Vec4& quaternion);
/// A frame fixed in a body: origin `point` (body axes), z axis along `axis`, x axis the body
/// axis least aligned with it made perpendicular (as the scene format's {"point", "axis"}).
/// @throws InputError if the axis is zero or a value is not finite.
JointFrame jointFrameFromAxis(const Vec3& point, const Vec3& axis);

// ----- bodies -------------------------------------------------------------------------------

/// @throws InputError (RigidBody3d) naming the body for a bad mass, inertia or orientation.
BodyIndex addRigidBody3d(System& sys, const std::string& name, const RigidBody3dProperties& props,
                         const FrameState3d& initial);
/// A spatial FFR body of a beam model (FfrBody3d); `initial` is the state of its floating
/// frame; qf0, qf0dot its initial elastic coordinates and rates (empty: zero).
/// @throws InputError naming the body (null model, wrong sizes, bad state).
BodyIndex addFlexibleBody3d(System& sys, const std::string& name, std::shared_ptr<const FfrBeamModel3d> model,
                            const FrameState3d& initial, const VecX& qf0 = {}, const VecX& qf0dot = {});
/// A spatial FFR body of given invariants (from another FE tool, or a beam model's
/// invariants changed): as above. @throws InputError naming the body and the invariant.
BodyIndex addFlexibleBody3d(System& sys, const std::string& name, FfrInvariants3d invariants,
                            const FrameState3d& initial, const VecX& qf0 = {}, const VecX& qf0dot = {});

// ----- joints -------------------------------------------------------------------------------

/// "spherical", "revolute", "prismatic", "cylindrical", "universal", "fixed", "planar".
/// @throws InputError listing the types for any other name.
SpatialJointType spatialJointTypeFromString(const std::string& type);

/// A joint between frame fi of body bi and frame fj of body bj (body axes; SpatialJoint).
ConstraintIndex addSpatialJoint(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                const JointFrame& fi, BodyIndex bj, const JointFrame& fj);
/// A joint placed by one frame in world axes, in the initial configuration
/// (jointFramesFromWorld: both body frames coincide with it there).
ConstraintIndex addSpatialJointAtWorld(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                       BodyIndex bj, const JointFrame& world);
/// A joint placed by a world point and, except for spherical and fixed joints (world axes
/// if none), its joint axis; a universal joint also needs xAxis (the cross's pin on body
/// bi). worldJointFrame(point, *axis, xAxis).
/// @throws InputError naming the joint for a missing axis or x axis, bad vectors, bodies
///         without a spatial frame or a flexible body without a node at the point.
ConstraintIndex addSpatialJointAtWorld(System& sys, const std::string& name, SpatialJointType type, BodyIndex bi,
                                       BodyIndex bj, const Vec3& point, const Vec3* axis = nullptr,
                                       const Vec3* xAxis = nullptr);

// ----- drivers ------------------------------------------------------------------------------

/// The angle of a spatial revolute or cylindrical joint (SpatialJointAngleDriver) = law(t).
/// @throws InputError naming the driver for a joint index out of range or another type.
ConstraintIndex addJointAngleDriver(System& sys, const std::string& name, ConstraintIndex joint, TimeLawPtr law);
/// The displacement of a spatial prismatic or cylindrical joint along its axis
/// (SpatialJointDisplacementDriver) = law(t).
ConstraintIndex addJointDisplacementDriver(System& sys, const std::string& name, ConstraintIndex joint,
                                           TimeLawPtr law);
/// The joint angle of a spatial revolute or cylindrical joint at the bodies' initial
/// coordinates (evaluateJointAngle), in (-pi, pi].
double initialJointAngle(const System& sys, ConstraintIndex joint);

// ----- forces -------------------------------------------------------------------------------

/// freeLength: the length at zero tension; none: the points' initial distance.
ForceIndex addSpatialSpringDamper(System& sys, const std::string& name, BodyIndex bi, const Vec3& pointI,
                                  BodyIndex bj, const Vec3& pointJ, double stiffness, double damping,
                                  std::optional<double> freeLength = std::nullopt, SpringLawPtr law = nullptr);
/// About a spatial revolute or cylindrical joint's axis; freeAngle: the angle of zero
/// torque, none: the joint's initial angle. law (both): a user law in place of the linear
/// one (core/user_function.hpp).
ForceIndex addSpatialRotationalSpringDamper(System& sys, const std::string& name, ConstraintIndex joint,
                                            double stiffness, double damping,
                                            std::optional<double> freeAngle = std::nullopt, SpringLawPtr law = nullptr);
/// Six-component bushing between frames fi and fj (SpatialBushing; translations along
/// and rotations about frame i's x, y, z); stiffness and damping >= 0.
ForceIndex addSpatialBushing(System& sys, const std::string& name, BodyIndex bi, const JointFrame& fi, BodyIndex bj,
                             const JointFrame& fj, const std::array<double, 6>& stiffness,
                             const std::array<double, 6>& damping);
/// A bushing placed by one frame in world axes, in the initial configuration: both body
/// frames coincide with it there (jointFramesFromWorld), so it starts undeflected.
ForceIndex addSpatialBushingAtWorld(System& sys, const std::string& name, BodyIndex bi, BodyIndex bj,
                                    const JointFrame& world, const std::array<double, 6>& stiffness,
                                    const std::array<double, 6>& damping);
/// Force (x, y, z) and torque (x, y, z) laws at a body point, world axes (null: zero; at
/// least one given).
ForceIndex addSpatialAppliedLoad(System& sys, const std::string& name, BodyIndex body, const Vec3& point,
                                 const std::array<TimeLawPtr, 6>& laws);

}  // namespace flexmbd
