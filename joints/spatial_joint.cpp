#include "joints/spatial_joint.hpp"

#include <Eigen/Dense>

#include "core/errors.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

const char* toString(SpatialJointType type) {
  switch (type) {
    case SpatialJointType::Spherical: return "spherical";
    case SpatialJointType::Revolute: return "revolute";
    case SpatialJointType::Prismatic: return "prismatic";
    case SpatialJointType::Cylindrical: return "cylindrical";
    case SpatialJointType::Universal: return "universal";
    case SpatialJointType::Fixed: return "fixed";
    case SpatialJointType::Planar: return "planar";
  }
  return "?";
}

namespace {

using Eq = SpatialJoint::Equation;

/// The constrained directions of each joint type (axes: 0 = x, 1 = y, 2 = z).
std::vector<Eq> equationsOf(SpatialJointType type) {
  const std::vector<Eq> point = {{Eq::Gap, 0, 0}, {Eq::Gap, 1, 0}, {Eq::Gap, 2, 0}};
  const std::vector<Eq> zAxis = {{Eq::AxisAxis, 2, 0}, {Eq::AxisAxis, 2, 1}};  // z_i stays normal to x_j, y_j
  const Eq twist{Eq::AxisAxis, 0, 1};                                          // x_i . y_j: rotation about z locked
  const std::vector<Eq> lateral = {{Eq::AxisGap, 0, 0}, {Eq::AxisGap, 1, 0}};  // no motion across z_i
  auto join = [](std::vector<Eq> a, const std::vector<Eq>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  switch (type) {
    case SpatialJointType::Spherical: return point;
    case SpatialJointType::Revolute: return join(point, zAxis);
    case SpatialJointType::Prismatic: return join(join(lateral, zAxis), {twist});
    case SpatialJointType::Cylindrical: return join(lateral, zAxis);
    case SpatialJointType::Universal: return join(point, {{Eq::AxisAxis, 0, 1}});
    case SpatialJointType::Fixed: return join(join(point, zAxis), {twist});
    case SpatialJointType::Planar: return {{Eq::AxisGap, 2, 0}, {Eq::AxisAxis, 2, 0}, {Eq::AxisAxis, 2, 1}};
  }
  return {};
}

void checkFrame(const JointFrame& f, const std::string& who) {
  for (int k = 0; k < 3; ++k) requireFinite(f.point[k], who + ": point[" + std::to_string(k) + "]");
  const Mat3& C = f.axes;
  if (!C.allFinite() || !((C.transpose() * C - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) ||
      !(C.determinant() > 0.0)) {
    throw InputError(who + ": axes: not orthonormal and right-handed (expected a rotation matrix)");
  }
}

}  // namespace

SpatialJoint::SpatialJoint(std::string name, SpatialJointType type, BodyIndex bodyI, const JointFrame& frameI,
                           BodyIndex bodyJ, const JointFrame& frameJ)
    : Constraint(std::move(name), {bodyI, bodyJ}), type_(type), frameI_(frameI), frameJ_(frameJ),
      equations_(equationsOf(type)) {
  const std::string who = "joint '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  checkFrame(frameI, who + " frame 0");
  checkFrame(frameJ, who + " frame 1");
}

void SpatialJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  KinematicsWork& w = out.work;
  FrameKinematics &fi = w.fi, &fj = w.fj;
  bodies[0].frame(frameI_.point, fi);
  bodies[1].frame(frameJ_.point, fj);
  const int ni = fi.numVelocities(), nj = fj.numVelocities(), n = ni + nj;
  const int qi = fi.numCoordinates(), qj = fj.numCoordinates(), nq = qi + qj;
  const int m = numEquations();
  // d = r_j - r_i and its Jacobian over [v_i; v_j]
  const Vec3 d = fj.r - fi.r;
  w.Jd.resize(3, n);
  w.Jd.leftCols(ni) = -fi.Jr;
  w.Jd.rightCols(nj) = fj.Jr;
  out.h.resize(m);
  out.G.resize(m, n);
  if (withHessians) {
    out.H.resize(m);
    w.Tinv.setZero(n, nq);  // T+ over the local columns, block-diagonal
    w.Tinv.topLeftCorner(ni, qi) = fi.Tinv;
    w.Tinv.bottomRightCorner(nj, qj) = fj.Tinv;
  }
  // a frame axis as a world vector u = A c with its Jacobian -u~ Jw (zero on the other body)
  auto axis = [&](bool onI, int k, Vec3& u, Mat3X& J) {
    const FrameKinematics& f = onI ? fi : fj;
    u = f.A * (onI ? frameI_ : frameJ_).axes.col(k);
    J.setZero(3, n);
    J.middleCols(onI ? 0 : ni, onI ? ni : nj) = -skew(u) * f.Jw;
  };
  // H += d(J_u^T x)/dq at fixed x for an axis u on body i or j:
  //   the body's curvature with weight (0, u x x), plus Jw^T (-x~) du/dq, du/dq = J_u T+
  auto axisCurvature = [&](bool onI, const Vec3& u, const Mat3X& Ju, const Vec3& x, MatX& H) {
    const FrameKinematics& f = onI ? fi : fj;
    const int r0 = onI ? 0 : ni, c0 = onI ? 0 : qi, nr = onI ? ni : nj, nc = onI ? qi : qj;
    bodies[onI ? 0 : 1].addCurvature(onI ? frameI_.point : frameJ_.point, Vec3::Zero(), u.cross(x),
                                     H.block(r0, c0, nr, nc));
    w.JT.noalias() = Ju * w.Tinv;  // 3 x nq
    H.middleRows(r0, nr).noalias() -= f.Jw.transpose() * (skew(x) * w.JT);
  };
  // H += d(J_d^T x)/dq at fixed x
  auto gapCurvature = [&](const Vec3& x, MatX& H) {
    bodies[0].addCurvature(frameI_.point, -x, Vec3::Zero(), H.block(0, 0, ni, qi));
    bodies[1].addCurvature(frameJ_.point, x, Vec3::Zero(), H.block(ni, qi, nj, qj));
  };
  // H += J_a^T (J_b T+) + J_b^T (J_a T+): the product rule's cross terms of h = a . b
  auto crossTerms = [&](const Mat3X& Ja, const Mat3X& Jb, MatX& H) {
    w.JT.noalias() = Jb * w.Tinv;
    H.noalias() += Ja.transpose() * w.JT;
    w.JT.noalias() = Ja * w.Tinv;
    H.noalias() += Jb.transpose() * w.JT;
  };
  Vec3 u, z;
  for (int e = 0; e < m; ++e) {
    const Eq& eq = equations_[e];
    MatX* H = withHessians ? &out.H[e] : nullptr;
    if (H) H->setZero(n, nq);
    switch (eq.kind) {
      case Eq::Gap: {
        out.h[e] = d[eq.a];
        out.G.row(e) = w.Jd.row(eq.a);
        if (H) gapCurvature(Vec3::Unit(eq.a), *H);
        break;
      }
      case Eq::AxisGap: {
        axis(true, eq.a, u, w.J1);
        out.h[e] = u.dot(d);
        out.G.row(e).noalias() = d.transpose() * w.J1 + u.transpose() * w.Jd;
        if (H) {
          axisCurvature(true, u, w.J1, d, *H);
          gapCurvature(u, *H);
          crossTerms(w.J1, w.Jd, *H);
        }
        break;
      }
      case Eq::AxisAxis: {
        axis(true, eq.a, u, w.J1);
        axis(false, eq.b, z, w.J2);
        out.h[e] = u.dot(z);
        out.G.row(e).noalias() = z.transpose() * w.J1 + u.transpose() * w.J2;
        if (H) {
          axisCurvature(true, u, w.J1, z, *H);
          axisCurvature(false, z, w.J2, u, *H);
          crossTerms(w.J1, w.J2, *H);
        }
        break;
      }
    }
  }
}

VecX SpatialJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  ConstraintEvaluation ev;
  evaluate(bodies, false, ev);
  const FrameKinematics& fi = ev.work.fi;
  const FrameKinematics& fj = ev.work.fj;
  const int ni = fi.numVelocities(), nj = fj.numVelocities();
  // generalised constraint force on a body: -G^T lambda over its columns; the wrench
  // (F, M) at the joint point that gives it: [Jr^T Jw^T] [F; M] = Q
  const bool onJ = nj > 0;
  const FrameKinematics& f = onJ ? fj : fi;
  const VecX Q = -(ev.G.middleCols(onJ ? ni : 0, onJ ? nj : ni).transpose() * lambda);
  MatX B(Q.size(), 6);
  B << f.Jr.transpose(), f.Jw.transpose();
  VecX wrench = B.colPivHouseholderQr().solve(Q);
  if (!onJ) wrench = -wrench;  // body j is the ground: the reaction on it, by Newton's third law
  return wrench;
}

}  // namespace flexmbd
