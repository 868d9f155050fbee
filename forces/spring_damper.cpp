#include "forces/spring_damper.hpp"

#include "core/errors.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

SpringDamper::SpringDamper(std::string name, BodyIndex bodyI, const Vec2& pointI,
                           BodyIndex bodyJ, const Vec2& pointJ, double stiffness, double damping,
                           double freeLength, SpringLawPtr law)
    : Force(std::move(name), {bodyI, bodyJ}),
      pointI_(pointI),
      pointJ_(pointJ),
      stiffness_(stiffness),
      damping_(damping),
      freeLength_(freeLength),
      law_(std::move(law)) {
  const std::string who = "force '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  for (int k = 0; k < 2; ++k) {
    requireFinite(pointI[k], who + ": points[0][" + std::to_string(k) + "]");
    requireFinite(pointJ[k], who + ": points[1][" + std::to_string(k) + "]");
  }
  requireFinite(stiffness, who + ": stiffness");
  requireFinite(damping, who + ": damping");
  requireFinite(freeLength, who + ": free_length");
  if (stiffness < 0.0) throw InputError(who + ": stiffness must be >= 0, got " + std::to_string(stiffness));
  if (damping < 0.0) throw InputError(who + ": damping must be >= 0, got " + std::to_string(damping));
  if (freeLength < 0.0) throw InputError(who + ": free_length must be >= 0, got " + std::to_string(freeLength));
}

double SpringDamper::length(const BodyStates& b) const {
  return (b[1].point(pointJ_, b.pointId(1), false).r - b[0].point(pointI_, b.pointId(0), false).r).norm();
}

void SpringDamper::addForce(double t, const BodyStates& b, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                            KinematicsWork& w) const {
  const bool withHessians = dQdq != nullptr;
  b[0].point(pointI_, b.pointId(0), withHessians, w.pi);
  b[1].point(pointJ_, b.pointId(1), withHessians, w.pj);
  makePointPair(w.pi, w.pj, withHessians, w.pair);
  const PointPair& p = w.pair;
  const double l = p.d.norm();
  if (!(l > 1e-12)) {
    throw InputError("force '" + name() + "': the two points coincide (length 0); the spring direction is undefined");
  }
  // l = |d|, e = d / l, dl/dq = e^T D, f = k (l - l0) + c dl/dt (or the user law f(t, l, ldot)
  // with k = df/dl, c = df/dldot), Q = -f (dl/dq)^T (Haug1989)
  const Vec2 e = p.d / l;
  RowVecX& eD = w.row;
  eD.noalias() = e.transpose() * p.D;
  const double ldot = eD.dot(v);
  const SpringLawValue law = springDamperValue(law_.get(), stiffness_, damping_, freeLength_, t, l, ldot,
                                               dQdq != nullptr || dQdv != nullptr, name());
  const double f = law.f, k = law.dfdx, c = law.dfdxdot;
  Q -= f * eD.transpose();
  if (dQdq) {
    // d2l/dq2 = He + D^T P D / l with He = e_x Hdx + e_y Hdy, P = I - e e^T, and
    // D^T P D = D^T D - eD^T eD; d(dl/dt)/dq = v^T d2l/dq2.
    MatX& He = w.hessian;
    He = e.x() * p.Hdx + e.y() * p.Hdy;
    const Vec2 Dv = p.D * v;
    RowVecX& dfdq = w.row2;
    dfdq.noalias() = ((Dv - e * e.dot(Dv)) / l).transpose() * p.D;
    dfdq.noalias() += v.transpose() * He;
    dfdq = k * eD + c * dfdq;
    dQdq->noalias() -= eD.transpose() * dfdq;
    *dQdq -= f * He;
    dQdq->noalias() -= (f / l) * p.D.transpose() * p.D;
    dQdq->noalias() += (f / l) * eD.transpose() * eD;
  }
  if (dQdv) dQdv->noalias() -= c * eD.transpose() * eD;
}

double SpringDamper::potentialEnergy(const BodyStates& b) const {
  if (law_) return 0.0;  // a user law has no potential the engine knows
  const double s = length(b) - freeLength_;
  return 0.5 * stiffness_ * s * s;
}

}  // namespace flexmbd
