#include "joints/frame_pair.hpp"

#include "core/errors.hpp"
#include "core/rotation_3d.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

void checkJointFrame(const JointFrame& f, const std::string& who) {
  for (int k = 0; k < 3; ++k) requireFinite(f.point[k], who + ": point[" + std::to_string(k) + "]");
  const Mat3& C = f.axes;
  if (!C.allFinite() || !((C.transpose() * C - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) ||
      !(C.determinant() > 0.0)) {
    throw InputError(who + ": axes: not orthonormal and right-handed (expected a rotation matrix)");
  }
}

void evaluateFrameEquations(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ,
                            const std::vector<FrameEquation>& equations, bool withHessians, ConstraintEvaluation& out) {
  FramePair pair(bodies, frameI, frameJ, withHessians, out.work);
  const int m = static_cast<int>(equations.size()), n = pair.numVelocities(), nq = pair.numCoordinates();
  out.h.resize(m);
  out.G.resize(m, n);
  if (withHessians) out.H.resize(m);
  for (int e = 0; e < m; ++e) {
    const FrameEquation& eq = equations[e];
    MatX* H = withHessians ? &out.H[e] : nullptr;
    if (H) H->setZero(n, nq);
    switch (eq.kind) {
      case FrameEquation::Gap: pair.gap(eq.a, out.h[e], out.G.row(e), H); break;
      case FrameEquation::AxisGap: pair.axisGap(eq.a, out.h[e], out.G.row(e), H); break;
      case FrameEquation::AxisAxis: pair.axisAxis(eq.a, eq.b, out.h[e], out.G.row(e), H); break;
    }
  }
}

FramePair::FramePair(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ, bool withH,
                     KinematicsWork& work)
    : bodies_(bodies), frameI_(frameI), frameJ_(frameJ), w_(work) {
  FrameKinematics &fi = w_.fi, &fj = w_.fj;
  bodies[0].frame(frameI.point, bodies.pointId(0), fi);
  bodies[1].frame(frameJ.point, bodies.pointId(1), fj);
  ni_ = fi.numVelocities();
  nj_ = fj.numVelocities();
  qi_ = fi.numCoordinates();
  qj_ = fj.numCoordinates();
  d_ = fj.r - fi.r;
  w_.Jd.resize(3, ni_ + nj_);
  w_.Jd.leftCols(ni_) = -fi.Jr;
  w_.Jd.rightCols(nj_) = fj.Jr;
  if (withH) {
    w_.Tinv.setZero(ni_ + nj_, qi_ + qj_);  // T+ over the local columns, block-diagonal
    w_.Tinv.topLeftCorner(ni_, qi_) = fi.Tinv;
    w_.Tinv.bottomRightCorner(nj_, qj_) = fj.Tinv;
  }
}

Vec3 FramePair::axisI(int a) const { return w_.fi.A * frameI_.axes.col(a); }
Vec3 FramePair::axisJ(int b) const { return w_.fj.A * frameJ_.axes.col(b); }

// a frame axis as a world vector u = A c with its Jacobian -u~ Jw (zero on the other body;
// Haug1989, ch. 9)
void FramePair::axis(bool onI, int k, Vec3& u, Mat3X& J) const {
  const FrameKinematics& f = onI ? w_.fi : w_.fj;
  u = onI ? axisI(k) : axisJ(k);
  J.setZero(3, ni_ + nj_);
  const Mat3 minusU = -skew(u);
  J.middleCols(onI ? 0 : ni_, onI ? ni_ : nj_).noalias() = minusU * f.Jw;
}

// H += d(J_u^T x)/dq at fixed x for an axis u on body i or j: the body's curvature with
// weight (0, u x x), plus Jw^T (-x~) du/dq with du/dq = J_u T+
void FramePair::axisCurvature(bool onI, const Vec3& u, const Mat3X& Ju, const Vec3& x, MatX& H) {
  const FrameKinematics& f = onI ? w_.fi : w_.fj;
  const int r0 = onI ? 0 : ni_, c0 = onI ? 0 : qi_, nr = onI ? ni_ : nj_, nc = onI ? qi_ : qj_;
  bodies_[onI ? 0 : 1].addCurvature(onI ? frameI_.point : frameJ_.point, bodies_.pointId(onI ? 0 : 1), Vec3::Zero(), u.cross(x),
                                    H.block(r0, c0, nr, nc));
  w_.JT.noalias() = Ju * w_.Tinv;  // 3 x nq
  const Mat3 X = skew(x);
  w_.JT2.noalias() = X * w_.JT;
  H.middleRows(r0, nr).noalias() -= f.Jw.transpose() * w_.JT2;
}

// H += d(J_d^T x)/dq at fixed x
void FramePair::gapCurvature(const Vec3& x, MatX& H) {
  bodies_[0].addCurvature(frameI_.point, bodies_.pointId(0), -x, Vec3::Zero(), H.block(0, 0, ni_, qi_));
  bodies_[1].addCurvature(frameJ_.point, bodies_.pointId(1), x, Vec3::Zero(), H.block(ni_, qi_, nj_, qj_));
}

// H += J_a^T (J_b T+) + J_b^T (J_a T+): the product rule's cross terms of h = a . b
void FramePair::crossTerms(const Mat3X& Ja, const Mat3X& Jb, MatX& H) {
  w_.JT.noalias() = Jb * w_.Tinv;
  H.noalias() += Ja.transpose() * w_.JT;
  w_.JT.noalias() = Ja * w_.Tinv;
  H.noalias() += Jb.transpose() * w_.JT;
}

}  // namespace flexmbd
