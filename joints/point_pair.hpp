// Relative kinematics of two body points: the building block of every planar joint.
#pragma once

#include "core/body.hpp"

namespace flexmbd {

/// d = r_j - r_i and the material angles at both points, with first and second
/// derivatives with respect to the local coordinates [q_i; q_j] (n_i + n_j).
struct PointPair {
  int ni = 0, nj = 0;
  Vec2 d = Vec2::Zero();
  Mat2X D;               ///< dd/dq, 2 x n
  MatX Hdx, Hdy;         ///< d2 d_k/dq2
  double phiI = 0.0, phiJ = 0.0;
  RowVecX JphiI, JphiJ;  ///< 1 x n (zero outside the body's block)
  MatX HphiI, HphiJ;     ///< n x n
  int n() const { return ni + nj; }
  MatX hessianD(const Vec2& w) const { return w.x() * Hdx + w.y() * Hdy; }
};

/// Combines the kinematics of point i (on the first body) and point j (second body);
/// the Hessian blocks only if withHessians (then both points must carry them).
PointPair makePointPair(const PointKinematics& pi, const PointKinematics& pj, bool withHessians = true);



}  // namespace flexmbd

#include <vector>

#include "core/constraint.hpp"

namespace flexmbd {

/// Scalar s = a_w^T d with a_w = A(phi_i) a the body-i axis `a` carried by the material
/// angle at point i; its gradient and Hessian (used by prismatic joints and drivers).
/// ds/dq = a_w^T D + (S a_w)^T d dphi_i/dq, and d2s/dq2 follows by the product rule.
void projectOnRotatingAxis(const PointPair& p, const Vec2& axisLocal, bool withHessian,
                           double& s, RowVecX& grad, MatX* hessian);

/// Base of constraints between a point of body i and a point of body j.
class TwoPointConstraint : public Constraint {
 public:
  TwoPointConstraint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                     const Vec2& pointJ);
  const Vec2& pointI() const { return pointI_; }
  const Vec2& pointJ() const { return pointJ_; }
  std::vector<std::pair<BodyIndex, Vec2>> attachments() const override {
    return {{bodies()[0], pointI_}, {bodies()[1], pointJ_}};
  }

 protected:
  /// Kinematics of the two points; Hessians only if withHessians (not in residuals).
  PointPair pair(const std::vector<BodyState>& bodies, bool withHessians) const;

 private:
  Vec2 pointI_, pointJ_;
};

}  // namespace flexmbd
