#include "joints/point_pair.hpp"

namespace flexmbd {

PointPair makePointPair(const PointKinematics& pi, const PointKinematics& pj, bool withHessians) {
  PointPair p;
  p.ni = static_cast<int>(pi.Jr.cols());
  p.nj = static_cast<int>(pj.Jr.cols());
  const int n = p.n();
  p.d = pj.r - pi.r;
  p.D.setZero(2, n);
  p.D.leftCols(p.ni) = -pi.Jr;
  p.D.rightCols(p.nj) = pj.Jr;
  p.phiI = pi.phi;
  p.phiJ = pj.phi;
  p.JphiI.setZero(n);
  p.JphiJ.setZero(n);
  p.JphiI.head(p.ni) = pi.Jphi;
  p.JphiJ.tail(p.nj) = pj.Jphi;
  if (!withHessians) return p;
  p.Hdx.setZero(n, n);
  p.Hdy.setZero(n, n);
  p.Hdx.topLeftCorner(p.ni, p.ni) = -pi.Hrx;
  p.Hdy.topLeftCorner(p.ni, p.ni) = -pi.Hry;
  p.Hdx.bottomRightCorner(p.nj, p.nj) = pj.Hrx;
  p.Hdy.bottomRightCorner(p.nj, p.nj) = pj.Hry;
  p.HphiI.setZero(n, n);
  p.HphiJ.setZero(n, n);
  p.HphiI.topLeftCorner(p.ni, p.ni) = pi.Hphi;
  p.HphiJ.bottomRightCorner(p.nj, p.nj) = pj.Hphi;
  return p;
}

}  // namespace flexmbd

#include "core/errors.hpp"

namespace flexmbd {

void projectOnRotatingAxis(const PointPair& p, const Vec2& axisLocal, bool withHessian,
                           double& s, RowVecX& grad, MatX* hessian) {
  const Vec2 a = rotation(p.phiI) * axisLocal;  // world axis
  const Vec2 sa = perp(a);                      // d a / d phi_i
  s = a.dot(p.d);
  const double sad = sa.dot(p.d);
  grad = a.transpose() * p.D + sad * p.JphiI;
  if (withHessian) {
    const RowVecX saD = sa.transpose() * p.D;
    *hessian = p.hessianD(a) + saD.transpose() * p.JphiI + p.JphiI.transpose() * saD -
               a.dot(p.d) * p.JphiI.transpose() * p.JphiI + sad * p.HphiI;
  }
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

PointPair TwoPointConstraint::pair(const std::vector<BodyState>& bodies, bool withHessians) const {
  return makePointPair(bodies[0].point(pointI_, withHessians),
                       bodies[1].point(pointJ_, withHessians), withHessians);
}

}  // namespace flexmbd
