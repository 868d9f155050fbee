/// @file
/// Drivers of spatial joints: the angle of a revolute (or cylindrical) joint and the
/// displacement of a prismatic (or cylindrical) joint, prescribed by a time law.
#pragma once

#include "joints/drivers.hpp"
#include "joints/frame_pair.hpp"

namespace flexmbd {

/// theta = atan2(y_i . x_j, x_i . x_j), the rotation of frame j about frame i's z axis,
/// with its gradient (1 x nv) and, if H is given, H = d(grad^T)/dq (nv x nq), using
/// `work` (its rows row..row6 and hessian; grad and H must be other storage).
void evaluateJointAngle(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ,
                        KinematicsWork& work, double& theta, RowVecX& grad, MatX* H);

/// Base of drivers between two body frames.
class FramePairConstraint : public Constraint {
 public:
  /// `kind` names the element in messages ("driver", "joint").
  /// @throws InputError if the bodies are the same or a frame is not a finite point and a rotation.
  FramePairConstraint(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                      const JointFrame& frameJ, const std::string& kind = "driver");
  const JointFrame& frameI() const { return frameI_; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], frameI_.point}, {bodies()[1], frameJ_.point}};
  }
  const JointFrame& frameJ() const { return frameJ_; }

 protected:
  JointFrame frameI_, frameJ_;
};

/// h = theta = atan2(y_i . x_j, x_i . x_j): the rotation of frame j about the z axis of
/// frame i, from x_i to x_j; known modulo 2 pi (equationPeriod), so any number of turns
/// can be driven. f = law(t).
class SpatialJointAngleDriver final : public LawDriver<FramePairConstraint> {
 public:
  SpatialJointAngleDriver(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                          const JointFrame& frameJ, TimeLawPtr law);
  std::string typeName() const override { return "joint_angle"; }
  double equationPeriod() const override;
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
};

/// h = z_i . (r_j - r_i): the displacement of frame j's origin along the z axis of frame i
/// (FramePair::axisGap, Haug1989, ch. 9).
class SpatialJointDisplacementDriver final : public LawDriver<FramePairConstraint> {
 public:
  SpatialJointDisplacementDriver(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                                 const JointFrame& frameJ, TimeLawPtr law);
  std::string typeName() const override { return "joint_displacement"; }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
};

}  // namespace flexmbd
