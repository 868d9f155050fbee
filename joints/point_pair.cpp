#include "joints/point_pair.hpp"

#include "core/errors.hpp"

namespace flexmbd {

void makePointPair(const PointKinematics& pi, const PointKinematics& pj, bool withHessians, PointPair& p) {
  // d = r_j - r_i, D = [-Jr_i, Jr_j]; Jphi_i, Jphi_j on their own body's columns
  p.ni = pi.numCoordinates();
  p.nj = pj.numCoordinates();
  const int n = p.n(), ni = p.ni, nj = p.nj;
  p.d = pj.r - pi.r;
  p.phiI = pi.phi;
  p.phiJ = pj.phi;
  // raw loops over the few columns (of sizes known only at run time): Eigen's block
  // assignments cost more in set-up than in copying here
  p.D.resize(2, n);
  p.JphiI.resize(n);
  p.JphiJ.resize(n);
  double* D = p.D.data();
  const double* Ji = pi.Jr.data();
  const double* Jj = pj.Jr.data();
  for (int k = 0; k < 2 * ni; ++k) D[k] = -Ji[k];
  for (int k = 0; k < 2 * nj; ++k) D[2 * ni + k] = Jj[k];
  for (int k = 0; k < ni; ++k) {
    p.JphiI[k] = pi.Jphi[k];
    p.JphiJ[k] = 0.0;
  }
  for (int k = 0; k < nj; ++k) {
    p.JphiI[ni + k] = 0.0;
    p.JphiJ[ni + k] = pj.Jphi[k];
  }
  if (!withHessians) return;
  for (MatX* H : {&p.Hdx, &p.Hdy, &p.HphiI, &p.HphiJ}) H->setZero(n, n);
  p.Hdx.topLeftCorner(ni, ni) = -pi.Hrx;
  p.Hdy.topLeftCorner(ni, ni) = -pi.Hry;
  p.Hdx.bottomRightCorner(nj, nj) = pj.Hrx;
  p.Hdy.bottomRightCorner(nj, nj) = pj.Hry;
  p.HphiI.topLeftCorner(ni, ni) = pi.Hphi;
  p.HphiJ.bottomRightCorner(nj, nj) = pj.Hphi;
}

void projectOnRotatingAxis(const PointPair& p, const Vec2& axisLocal, double& s, RowVecX& grad, MatX* hessian,
                           RowVecX& saD) {
  const Vec2 a = rotation(p.phiI) * axisLocal;  // world axis
  const Vec2 sa = perp(a);                      // d a / d phi_i
  s = a.dot(p.d);
  const double sad = sa.dot(p.d);
  grad.noalias() = a.transpose() * p.D;
  grad += sad * p.JphiI;
  if (!hessian) return;
  // a_x Hdx + a_y Hdy + (S a)^T D (x) Jphi_i + Jphi_i (x) (S a)^T D - s Jphi_i^T Jphi_i + (S a . d) Hphi_i
  saD.noalias() = sa.transpose() * p.D;
  MatX& H = *hessian;
  H = a.x() * p.Hdx + a.y() * p.Hdy + sad * p.HphiI;
  H.noalias() += saD.transpose() * p.JphiI;
  H.noalias() += p.JphiI.transpose() * saD;
  H.noalias() -= s * p.JphiI.transpose() * p.JphiI;
}

TwoPointConstraint::TwoPointConstraint(std::string name, BodyIndex bodyI, const Vec2& pointI,
                                       BodyIndex bodyJ, const Vec2& pointJ)
    : Constraint(std::move(name), {bodyI, bodyJ}), pointI_(pointI), pointJ_(pointJ) {
  if (bodyI == bodyJ) {
    throw InputError("joint '" + this->name() + "': connects a body to itself; expected two different bodies");
  }
  for (int k = 0; k < 2; ++k) {
    requireFinite(pointI[k], "joint '" + this->name() + "': points[0][" + std::to_string(k) + "]");
    requireFinite(pointJ[k], "joint '" + this->name() + "': points[1][" + std::to_string(k) + "]");
  }
}

const PointPair& TwoPointConstraint::pair(const BodyStates& bodies, bool withHessians, KinematicsWork& w) const {
  bodies[0].point(pointI_, bodies.pointId(0), withHessians, w.pi);
  bodies[1].point(pointJ_, bodies.pointId(1), withHessians, w.pj);
  makePointPair(w.pi, w.pj, withHessians, w.pair);
  return w.pair;
}

}  // namespace flexmbd
