/// @file
/// Joint frames placed in the world: a joint given by a world point and world axes in the
/// initial configuration becomes one frame on each body, in body axes (docs/spatial.md,
/// "Joints placed in the world"). Used by the scene reader ("world" of a spatial joint)
/// and from C++:
///   const JointFrame w = worldJointFrame(Vec3(0, 0, 1), Vec3::UnitY(), nullptr, "hinge");
///   const auto [fi, fj] = jointFramesFromWorld(sys, crank, rod, w, "joint 'hinge'");
///   sys.addConstraint(std::make_unique<SpatialJoint>("hinge", SpatialJointType::Revolute,
///                                                    crank, fi, rod, fj));
#pragma once

#include <array>
#include <string>

#include "core/system.hpp"
#include "joints/frame_pair.hpp"

namespace flexmbd {

/// Position (world) and orientation (body axes in world axes) of a body's reference frame.
struct BodyPose {
  Vec3 position = Vec3::Zero();
  Mat3 orientation = Mat3::Identity();
};

/// The reference frame of `body` at its coordinates q: the ground's is the world frame;
/// a spatial rigid body's is (R, A(p)) at its centre of mass; a spatial flexible body's
/// is its floating frame (R, A(p)) (coordinates (R, p, ...) for both).
/// @throws InputError naming `who` for a body without a spatial frame (planar bodies).
BodyPose spatialBodyPose(const Body& body, const ConstVecRef& q, const std::string& who);

/// The axes (columns x, y, z, world axes) of a frame with z along `z`: x is `xHint`
/// made perpendicular to z (Gram-Schmidt, GolubVanLoan2013), or without a hint the world axis least
/// aligned with z made perpendicular; y = z x x.
/// @throws InputError naming `who` if z or xHint cannot be normalised (directionProblem,
///         core/magnitude_checks.hpp: not finite, zero, or shorter than 1e-100), or xHint
///         is parallel to z (within 1e-9 of the product of the lengths).
Mat3 frameAxesFromZ(const Vec3& z, const Vec3* xHint, const std::string& who);

/// A world frame: origin `point`, z axis `axis`, x axis `xHint` (optional; see frameAxesFromZ).
/// @throws InputError as frameAxesFromZ, or for a non-finite point.
JointFrame worldJointFrame(const Vec3& point, const Vec3& axis, const Vec3* xHint, const std::string& who);

/// The frame fixed in `body` that coincides with the world frame `world` when the body is
/// at its initial coordinates: point u = A^T (p - R), axes A^T C. A flexible body is taken
/// undeformed (its initial elastic coordinates are not used) and u must be one of its nodes.
/// @throws InputError naming `who` (planar body; no node of a flexible body at the point).
JointFrame bodyFrameFromWorld(const Body& body, const JointFrame& world, const std::string& who);

/// Both frames of a joint between bodies bi and bj placed by one world frame: the frames
/// coincide in the initial configuration (every joint type's equations hold there).
std::array<JointFrame, 2> jointFramesFromWorld(const System& sys, BodyIndex bi, BodyIndex bj,
                                               const JointFrame& world, const std::string& who);

}  // namespace flexmbd
