/// @file
/// Kinematics of body points with their first and second derivatives: what bodies give
/// to joints and force elements, and the working memory their evaluations reuse.
#pragma once

#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// Position and material angle of one point of a body, with first and second
/// derivatives with respect to n coordinates q (all of the body's, or the ones a joint
/// uses). Joints and forces are written once in terms of this, whatever the body type.
/// Filled by Body::pointKinematics into an existing object, whose memory is reused: the
/// Hessians are valid only after a call with withHessians (otherwise left as they were).
struct PointKinematics {
  Vec2 r = Vec2::Zero();  ///< world position of the point
  double phi = 0.0;       ///< world angle of the material cross-section at the point
  Mat2X Jr;               ///< dr/dq, 2 x n
  RowVecX Jphi;           ///< dphi/dq, 1 x n
  MatX Hrx, Hry;          ///< d2 r_x/dq2, d2 r_y/dq2, n x n
  MatX Hphi;              ///< d2 phi/dq2, n x n
  int numCoordinates() const { return static_cast<int>(Jr.cols()); }
  /// Sizes for n coordinates and zeroes the derivatives (the Hessians only if
  /// withHessians). Allocates only when n grows.
  void reset(int n, bool withHessians) {
    Jr.setZero(2, n);
    Jphi.setZero(n);
    if (!withHessians) return;
    Hrx.setZero(n, n);
    Hry.setZero(n, n);
    Hphi.setZero(n, n);
  }
  /// sum_k w_k d2 r_k/dq2 (n x n).
  MatX hessianR(const Vec2& w) const { return w.x() * Hrx + w.y() * Hry; }
};

/// Spatial kinematics of the material frame at one body point, over the velocities and
/// coordinates a joint uses (see BodyState): what spatial joints are written in. The
/// second derivatives are supplied as curvature terms d/dq (Jr^T w_r + Jw^T w_w) for given
/// weights (Body::addFrameCurvature), never as per-component Hessians.
struct FrameKinematics {
  Vec3 r = Vec3::Zero();      ///< world position of the point
  Mat3 A = Mat3::Identity();  ///< orientation of the material frame at the point (world axes)
  Mat3X Jr;                   ///< r' = Jr v, 3 x nv_used
  Mat3X Jw;                   ///< angular velocity (world axes) = Jw v, 3 x nv_used
  MatX Tinv;                  ///< T+ over the used velocities and coordinates, nv_used x nq_used
  int numVelocities() const { return static_cast<int>(Jr.cols()); }
  int numCoordinates() const { return static_cast<int>(Tinv.cols()); }
};

/// d = r_j - r_i and the material angles at both points, with first and second
/// derivatives with respect to the local coordinates [q_i; q_j] (n_i + n_j). The same
/// reuse rule as PointKinematics.
struct PointPair {
  int ni = 0, nj = 0;
  Vec2 d = Vec2::Zero();
  Mat2X D;               ///< dd/dq, 2 x n
  MatX Hdx, Hdy;         ///< d2 d_k/dq2
  double phiI = 0.0, phiJ = 0.0;
  RowVecX JphiI, JphiJ;  ///< 1 x n (zero outside the body's block)
  MatX HphiI, HphiJ;     ///< n x n
  int n() const { return ni + nj; }
};

/// Working memory of one constraint or force evaluation, kept by the caller between
/// calls so that repeated evaluations allocate nothing.
struct KinematicsWork {
  PointKinematics pi, pj;  ///< the two attachment points
  PointPair pair;          ///< their relative kinematics
  RowVecX row, row2;       ///< 1 x n rows (gradients, products)
  MatX hessian;            ///< an n x n matrix
  FrameKinematics fi, fj;  ///< spatial joints: the two frames
  Mat3X J1, J2, Jd;        ///< spatial joints: Jacobians of two vectors and of r_j - r_i (3 x nv)
  MatX C, Tinv, JT, JT2;   ///< spatial joints: a curvature term, T+ (nv x nq), products
  RowVecX row3, row4, row5, row6, row7;  ///< more 1 x n rows
};

}  // namespace flexmbd
