/// @file
/// Relative kinematics of two body points: the building block of every planar joint.
#pragma once

#include <vector>

#include "core/constraint.hpp"

namespace flexmbd {

/// Combines the kinematics of point i (on the first body) and point j (second body) into
/// `out`; the Hessian blocks only if withHessians (then both points must carry them).
/// Allocates nothing once `out` has been filled for as many coordinates.
void makePointPair(const PointKinematics& pi, const PointKinematics& pj, bool withHessians, PointPair& out);

/// Scalar s = a_w^T d (Haug1989) with a_w = A(phi_i) a the body-i axis `a` carried by the material
/// angle at point i; its gradient and, if hessian is given, its Hessian (used by
/// prismatic joints and drivers). ds/dq = a_w^T D + (S a_w)^T d dphi_i/dq, and d2s/dq2
/// follows by the product rule. `work` is a 1 x n row of working memory.
void projectOnRotatingAxis(const PointPair& p, const Vec2& axisLocal, double& s, RowVecX& grad, MatX* hessian,
                           RowVecX& work);

/// Base of constraints between a point of body i and a point of body j.
class TwoPointConstraint : public Constraint {
 public:
  TwoPointConstraint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                     const Vec2& pointJ);
  const Vec2& pointI() const { return pointI_; }
  const Vec2& pointJ() const { return pointJ_; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], lift(pointI_)}, {bodies()[1], lift(pointJ_)}};
  }

 protected:
  /// Kinematics of the two points into work.pair (returned); Hessians only if
  /// withHessians (not in residuals).
  const PointPair& pair(const BodyStates& bodies, bool withHessians, KinematicsWork& work) const;

 private:
  Vec2 pointI_, pointJ_;
};

}  // namespace flexmbd
