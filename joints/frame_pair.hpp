/// @file
/// Relative kinematics of two body frames and the three scalar primitives spatial joints
/// and drivers are written in (Haug1989, ch. 9): with d = r_j - r_i,
///   gap(k)        = e_k . d        (world axis k)
///   axisGap(a)    = x_a^i . d      (along axis a of frame i)
///   axisAxis(a,b) = x_a^i . x_b^j  (axes of the two frames)
/// each with its velocity gradient (1 x nv) and its H = d(G^T)/dq (nv x nq).
#pragma once

#include <string>
#include <vector>

#include "core/constraint.hpp"

namespace flexmbd {

/// A frame fixed in a body: origin (body axes) and axes (columns x, y, z in body axes).
struct JointFrame {
  Vec3 point = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
};

/// @throws InputError naming `who` unless the frame's point is finite and its axes are a rotation.
void checkJointFrame(const JointFrame& f, const std::string& who);

/// One scalar equation between two frames, a primitive below (axes: 0 = x, 1 = y, 2 = z).
struct FrameEquation {
  enum Kind { Gap, AxisGap, AxisAxis } kind;
  int a = 0, b = 0;
};

/// h, G and, if withHessians, every H of the `equations` between the two frames (the
/// joints written in the primitives: SpatialJoint, PointGapJoint). Allocates nothing once
/// `out` holds as many equations and columns.
void evaluateFrameEquations(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ,
                            const std::vector<FrameEquation>& equations, bool withHessians, ConstraintEvaluation& out);

/// The two frames' kinematics at a state (in `work`, whose memory it reuses).
class FramePair {
 public:
  /// withH: prepare the second derivatives (T+ over the local columns).
  FramePair(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ, bool withH,
            KinematicsWork& work);
  int numVelocities() const { return ni_ + nj_; }
  int numCoordinates() const { return qi_ + qj_; }
  const Vec3& d() const { return d_; }
  /// T+ over the local columns (nv x nq; only with withH): a velocity gradient G gives
  /// the coordinate gradient G T+.
  const MatX& Tinv() const { return w_.Tinv; }
  /// Each primitive: its value into h, its gradient into G (a 1 x nv row), and H += its
  /// d(G^T)/dq if H is given (sized nv x nq by the caller).
  template <class Row>
  void gap(int k, double& h, Row&& G, MatX* H);
  template <class Row>
  void axisGap(int a, double& h, Row&& G, MatX* H);
  template <class Row>
  void axisAxis(int a, int b, double& h, Row&& G, MatX* H);
  /// World axis a of frame i / j.
  Vec3 axisI(int a) const;
  Vec3 axisJ(int b) const;
  /// d(d)/dv (3 x nv).
  const Mat3X& Jd() const { return w_.Jd; }
  /// H += d(Jd^T x)/dq at fixed x (nv x nq).
  void gapCurvature(const Vec3& x, MatX& H);

 private:
  void axis(bool onI, int k, Vec3& u, Mat3X& J) const;
  void axisCurvature(bool onI, const Vec3& u, const Mat3X& Ju, const Vec3& x, MatX& H);
  void crossTerms(const Mat3X& Ja, const Mat3X& Jb, MatX& H);

  const BodyStates& bodies_;
  const JointFrame &frameI_, &frameJ_;
  KinematicsWork& w_;
  int ni_ = 0, nj_ = 0, qi_ = 0, qj_ = 0;
  Vec3 d_;
};

template <class Row>
void FramePair::gap(int k, double& h, Row&& G, MatX* H) {
  h = d_[k];
  G = w_.Jd.row(k);
  if (H) gapCurvature(Vec3::Unit(k), *H);
}

template <class Row>
void FramePair::axisGap(int a, double& h, Row&& G, MatX* H) {
  Vec3 u;
  axis(true, a, u, w_.J1);
  h = u.dot(d_);
  G.noalias() = d_.transpose() * w_.J1;
  G.noalias() += u.transpose() * w_.Jd;
  if (!H) return;
  axisCurvature(true, u, w_.J1, d_, *H);
  gapCurvature(u, *H);
  crossTerms(w_.J1, w_.Jd, *H);
}

template <class Row>
void FramePair::axisAxis(int a, int b, double& h, Row&& G, MatX* H) {
  Vec3 u, z;
  axis(true, a, u, w_.J1);
  axis(false, b, z, w_.J2);
  h = u.dot(z);
  G.noalias() = z.transpose() * w_.J1;
  G.noalias() += u.transpose() * w_.J2;
  if (!H) return;
  axisCurvature(true, u, w_.J1, z, *H);
  axisCurvature(false, z, w_.J2, u, *H);
  crossTerms(w_.J1, w_.J2, *H);
}

}  // namespace flexmbd
