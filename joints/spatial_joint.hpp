/// @file
/// Spatial joints as a pair of frames plus the constrained directions: spherical, revolute,
/// prismatic, cylindrical, universal, fixed and planar (docs/spatial.md).
#pragma once

#include <vector>

#include "core/constraint.hpp"
#include "joints/frame_pair.hpp"

namespace flexmbd {

enum class SpatialJointType { Spherical, Revolute, Prismatic, Cylindrical, Universal, Fixed, Planar };
/// "spherical", "revolute", ...
const char* toString(SpatialJointType type);

/// The joint's equations, each one of three primitives of the frames i (on body i) and j
/// (Haug1989, ch. 9): d = r_j - r_i,
///   Gap(k):       e_k . d = 0            (world axis k: the points coincide along it)
///   AxisGap(a):   x_a^i . d = 0          (no relative motion along axis a of frame i)
///   AxisAxis(a,b): x_a^i . x_b^j = 0     (axes stay perpendicular: rotation locked)
/// Joint axes are the z axes of the frames (revolute: rotation about z; prismatic and
/// cylindrical: translation along z; planar: motion in the frames' x-y plane). The
/// universal (Cardan) joint's cross joins frame i's x axis and frame j's y axis.
class SpatialJoint final : public Constraint {
 public:
  using Equation = FrameEquation;
  /// @throws InputError naming the joint if the bodies are the same or a frame's axes are
  /// not orthonormal and right-handed.
  SpatialJoint(std::string name, SpatialJointType type, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
               const JointFrame& frameJ);

  SpatialJointType type() const { return type_; }
  const JointFrame& frameI() const { return frameI_; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], frameI_.point}, {bodies()[1], frameJ_.point}};
  }
  const JointFrame& frameJ() const { return frameJ_; }
  int numEquations() const override { return static_cast<int>(equations_.size()); }
  std::string typeName() const override { return toString(type_); }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  /// fx, fy, fz, mx, my, mz: the force and the moment about the joint point (world axes)
  /// that the joint exerts on body j (on body i, negated, if j is the ground).
  std::vector<std::string> reactionNames() const override { return {"fx", "fy", "fz", "mx", "my", "mz"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;

 private:
  SpatialJointType type_;
  JointFrame frameI_, frameJ_;
  std::vector<Equation> equations_;
};

}  // namespace flexmbd
