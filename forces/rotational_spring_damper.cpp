#include "forces/rotational_spring_damper.hpp"

#include "core/errors.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

RotationalSpringDamper::RotationalSpringDamper(std::string name, BodyIndex bodyI,
                                               const Vec2& pointI, BodyIndex bodyJ,
                                               const Vec2& pointJ, double stiffness,
                                               double damping, double freeAngle, SpringLawPtr law)
    : Force(std::move(name), {bodyI, bodyJ}),
      pointI_(pointI),
      pointJ_(pointJ),
      stiffness_(stiffness),
      damping_(damping),
      freeAngle_(freeAngle),
      law_(std::move(law)) {
  const std::string who = "force '" + this->name() + "'";
  requireFinite(stiffness, who + ": stiffness");
  requireFinite(damping, who + ": damping");
  requireFinite(freeAngle, who + ": free_angle");
  if (stiffness < 0.0) throw InputError(who + ": stiffness must be >= 0, got " + std::to_string(stiffness));
  if (damping < 0.0) throw InputError(who + ": damping must be >= 0, got " + std::to_string(damping));
}

void RotationalSpringDamper::addForce(double t, const BodyStates& b, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                                      KinematicsWork& w) const {
  const bool withHessians = dQdq != nullptr;
  b[0].point(pointI_, b.pointId(0), withHessians, w.pi);
  b[1].point(pointJ_, b.pointId(1), withHessians, w.pj);
  makePointPair(w.pi, w.pj, withHessians, w.pair);
  const PointPair& p = w.pair;
  // phi = phi_j - phi_i, J = dphi/dq, tau = k (phi - phi0) + c J v (or the user law
  // tau(t, phi, phidot) with k = dtau/dphi, c = dtau/dphidot), Q = -tau J^T (Haug1989)
  RowVecX& J = w.row;
  J = p.JphiJ - p.JphiI;
  const double phi = p.phiJ - p.phiI;
  const SpringLawValue law = springDamperValue(law_.get(), stiffness_, damping_, freeAngle_, t, phi, J.dot(v),
                                               dQdq != nullptr || dQdv != nullptr, name());
  const double tau = law.f, k = law.dfdx, c = law.dfdxdot;
  Q -= tau * J.transpose();
  if (dQdq) {
    // dQ/dq = -J^T (k J + c v^T H) - tau H with H = d2phi/dq2
    MatX& H = w.hessian;
    H = p.HphiJ - p.HphiI;
    RowVecX& dtau = w.row2;
    dtau.noalias() = v.transpose() * H;
    dtau = k * J + c * dtau;
    dQdq->noalias() -= J.transpose() * dtau;
    *dQdq -= tau * H;
  }
  if (dQdv) dQdv->noalias() -= c * J.transpose() * J;
}

double RotationalSpringDamper::potentialEnergy(const BodyStates& b) const {
  if (law_) return 0.0;  // a user law has no potential the engine knows
  const double phi = b[1].point(pointJ_, b.pointId(1), false).phi -
                     b[0].point(pointI_, b.pointId(0), false).phi;
  return 0.5 * stiffness_ * (phi - freeAngle_) * (phi - freeAngle_);
}

}  // namespace flexmbd
