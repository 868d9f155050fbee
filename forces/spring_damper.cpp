#include "forces/spring_damper.hpp"

#include "core/errors.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {

SpringDamper::SpringDamper(std::string name, BodyIndex bodyI, const Vec2& pointI,
                           BodyIndex bodyJ, const Vec2& pointJ, double stiffness, double damping,
                           double freeLength)
    : Force(std::move(name), {bodyI, bodyJ}),
      pointI_(pointI),
      pointJ_(pointJ),
      stiffness_(stiffness),
      damping_(damping),
      freeLength_(freeLength) {
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

double SpringDamper::length(const std::vector<BodyState>& b) const {
  return (b[1].point(pointJ_, false).r - b[0].point(pointI_, false).r)
      .norm();
}

void SpringDamper::addForce(double, const std::vector<BodyState>& b, const VecX& v, VecX& Q,
                            MatX* dQdq, MatX* dQdv) const {
  const bool withHessians = dQdq != nullptr;
  const PointPair p = makePointPair(b[0].point(pointI_, withHessians),
                                    b[1].point(pointJ_, withHessians), withHessians);
  const double l = p.d.norm();
  if (!(l > 1e-12)) {
    throw InputError("force '" + name() + "': the two points coincide (length 0); the spring direction is undefined");
  }
  const Vec2 e = p.d / l;
  const RowVecX eD = e.transpose() * p.D;  // dl/dq
  const double ldot = eD.dot(v);
  const double f = stiffness_ * (l - freeLength_) + damping_ * ldot;
  Q -= f * eD.transpose();
  if (dQdq) {
    const MatX He = p.hessianD(e);
    const Mat2 P = Mat2::Identity() - e * e.transpose();
    const MatX DPD = p.D.transpose() * P * p.D / l;  // d(D^T e)/dq without Hessian part
    const RowVecX dldotdq = v.transpose() * DPD + v.transpose() * He;
    const RowVecX dfdq = stiffness_ * eD + damping_ * dldotdq;
    *dQdq -= eD.transpose() * dfdq + f * (He + DPD);
  }
  if (dQdv) *dQdv -= damping_ * eD.transpose() * eD;
}

double SpringDamper::potentialEnergy(const std::vector<BodyState>& b) const {
  const double s = length(b) - freeLength_;
  return 0.5 * stiffness_ * s * s;
}

}  // namespace flexmbd
