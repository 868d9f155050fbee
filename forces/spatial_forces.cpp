#include "forces/spatial_forces.hpp"

#include "core/errors.hpp"
#include "core/user_function.hpp"
#include "forces/applied_load.hpp"
#include "joints/frame_pair.hpp"
#include "joints/spatial_drivers.hpp"

#include <cmath>

namespace flexmbd {

SpatialAppliedLoad::SpatialAppliedLoad(std::string name, BodyIndex body, const Vec3& point,
                                       std::array<TimeLawPtr, 6> laws)
    : Force(std::move(name), {body}), point_(point), laws_(std::move(laws)) {
  requireLoadableBody(body, "force '" + this->name() + "'");
  for (int k = 0; k < 3; ++k) requireFinite(point[k], "force '" + this->name() + "': point[" + std::to_string(k) + "]");
  bool any = false;
  for (const auto& l : laws_) any = any || l != nullptr;
  if (!any) throw InputError("force '" + this->name() + "': no force or torque law given");
}

void SpatialAppliedLoad::addForce(double t, const BodyStates& bodies, const VecX&, VecX& Q, MatX* dQdq, MatX*,
                                  KinematicsWork& w) const {
  Vec3 F = Vec3::Zero(), M = Vec3::Zero();
  try {
    for (int k = 0; k < 3; ++k) {
      if (laws_[k]) F[k] = laws_[k]->value(t);
      if (laws_[3 + k]) M[k] = laws_[3 + k]->value(t);
    }
  } catch (const UserFunctionError& e) {  // a user law raised: name the force
    rethrowWithOwner(e, "force '" + name() + "'");
  }
  bodies[0].frame(point_, bodies.pointId(0), w.fi);
  Q.noalias() += w.fi.Jr.transpose() * F;
  Q.noalias() += w.fi.Jw.transpose() * M;
  if (dQdq) bodies[0].addCurvature(point_, bodies.pointId(0), F, M, *dQdq);
}

SpatialSpringDamper::SpatialSpringDamper(std::string name, BodyIndex bodyI, const Vec3& pointI, BodyIndex bodyJ,
                                         const Vec3& pointJ, double stiffness, double damping, double freeLength,
                                         SpringLawPtr law)
    : Force(std::move(name), {bodyI, bodyJ}), pointI_(pointI), pointJ_(pointJ), stiffness_(stiffness),
      damping_(damping), freeLength_(freeLength), law_(std::move(law)) {
  const std::string who = "force '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  for (int k = 0; k < 3; ++k) {
    requireFinite(pointI[k], who + ": points[0][" + std::to_string(k) + "]");
    requireFinite(pointJ[k], who + ": points[1][" + std::to_string(k) + "]");
  }
  requireFinite(stiffness, who + ": stiffness");
  requireFinite(damping, who + ": damping");
  requireFinite(freeLength, who + ": free_length");
  if (stiffness < 0.0 || damping < 0.0 || freeLength < 0.0) {
    throw InputError(who + ": stiffness, damping and free_length must be >= 0");
  }
}

double SpatialSpringDamper::length(const BodyStates& bodies) const {
  KinematicsWork w;
  JointFrame fi, fj;
  fi.point = pointI_;
  fj.point = pointJ_;
  return FramePair(bodies, fi, fj, false, w).d().norm();
}

double SpatialSpringDamper::potentialEnergy(const BodyStates& bodies) const {
  if (law_) return 0.0;  // a user law has no potential the engine knows
  const double s = length(bodies) - freeLength_;
  return 0.5 * stiffness_ * s * s;
}

void SpatialSpringDamper::addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                                   KinematicsWork& w) const {
  JointFrame fi, fj;
  fi.point = pointI_;
  fj.point = pointJ_;
  FramePair pair(bodies, fi, fj, dQdq != nullptr, w);
  const double l = pair.d().norm();
  if (!(l > 1e-12)) {
    throw InputError("force '" + name() + "': the two points coincide (length 0); the spring direction is undefined");
  }
  // grad l = e^T Jd;  l' = grad l v;  f = k (l - l0) + c l' (or the user law f(t, l, l') with
  // k = df/dl, c = df/dl');  Q = -f grad l^T (Shabana2005, ch. 7)
  const Vec3 e = pair.d() / l;
  RowVecX& gradL = w.row;
  gradL.noalias() = e.transpose() * pair.Jd();
  const SpringLawValue law = springDamperValue(law_.get(), stiffness_, damping_, freeLength_, t, l, gradL.dot(v),
                                               dQdq != nullptr || dQdv != nullptr, name());
  const double f = law.f, k = law.dfdx, c = law.dfdxdot;
  Q.noalias() -= f * gradL.transpose();
  if (dQdv) {
    w.row3 = c * gradL;
    dQdv->noalias() -= gradL.transpose() * w.row3;
  }
  if (!dQdq) return;
  // H_l = d(grad l^T)/dq = C_d(e) + Jd^T (I - e e^T) / l Jd T+;  dl/dq = grad l T+;
  // dl'/dq = v^T H_l;  dQ/dq = -(grad l^T df/dq + f H_l)
  MatX& Hl = w.hessian;
  Hl.setZero(pair.numVelocities(), pair.numCoordinates());
  pair.gapCurvature(e, Hl);
  const Mat3 P = (Mat3::Identity() - e * e.transpose()) / l;
  w.JT.noalias() = pair.Jd() * pair.Tinv();
  w.JT2.noalias() = P * w.JT;
  Hl.noalias() += pair.Jd().transpose() * w.JT2;
  RowVecX& dfdq = w.row2;
  dfdq.noalias() = gradL * pair.Tinv();
  dfdq *= k;
  w.row4.noalias() = v.transpose() * Hl;
  dfdq += c * w.row4;
  dQdq->noalias() -= gradL.transpose() * dfdq;
  *dQdq -= f * Hl;
}

SpatialRotationalSpringDamper::SpatialRotationalSpringDamper(std::string name, BodyIndex bodyI,
                                                             const JointFrame& frameI, BodyIndex bodyJ,
                                                             const JointFrame& frameJ, double stiffness,
                                                             double damping, double freeAngle, SpringLawPtr law)
    : Force(std::move(name), {bodyI, bodyJ}), frameI_(frameI), frameJ_(frameJ), stiffness_(stiffness),
      damping_(damping), freeAngle_(freeAngle), law_(std::move(law)) {
  const std::string who = "force '" + this->name() + "'";
  requireFinite(stiffness, who + ": stiffness");
  requireFinite(damping, who + ": damping");
  requireFinite(freeAngle, who + ": free_angle");
  if (stiffness < 0.0 || damping < 0.0) throw InputError(who + ": stiffness and damping must be >= 0");
}

double SpatialRotationalSpringDamper::potentialEnergy(const BodyStates& bodies) const {
  if (law_) return 0.0;  // a user law has no potential the engine knows
  KinematicsWork w;
  double theta = 0.0;
  evaluateJointAngle(bodies, frameI_, frameJ_, w, theta, w.row7, nullptr);
  const double a = std::remainder(theta - freeAngle_, 2.0 * M_PI);
  return 0.5 * stiffness_ * a * a;
}

void SpatialRotationalSpringDamper::addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq,
                                             MatX* dQdv, KinematicsWork& w) const {
  // tau = -k a - c theta', theta' = grad v;  Q = tau grad^T (Haug1989);
  // dQ/dq = tau H + grad^T dtau/dq, dtau/dq = -k grad T+ - c v^T H;  dQ/dv = -c grad^T grad
  double theta = 0.0;
  RowVecX& grad = w.row7;
  MatX& H = w.C;
  evaluateJointAngle(bodies, frameI_, frameJ_, w, theta, grad, dQdq ? &H : nullptr);
  const double a = std::remainder(theta - freeAngle_, 2.0 * M_PI);
  // the linear law on a (x0 = 0), or the user law on theta = theta0 + a (k = dlaw/dtheta, c = dlaw/dtheta')
  const SpringLawValue law = springDamperValue(law_.get(), stiffness_, damping_, 0.0, t, law_ ? freeAngle_ + a : a,
                                               grad.dot(v), dQdq != nullptr || dQdv != nullptr, name());
  const double tau = -law.f, k = law.dfdx, c = law.dfdxdot;
  Q.noalias() += tau * grad.transpose();
  if (dQdv) {
    w.row6 = c * grad;  // (rows sized nv; row3, row4 are nq-long: not reused across sizes)
    dQdv->noalias() -= grad.transpose() * w.row6;
  }
  if (!dQdq) return;
  w.row3.noalias() = grad * w.Tinv;
  w.row3 *= -k;
  w.row4.noalias() = v.transpose() * H;
  w.row3 -= c * w.row4;
  *dQdq += tau * H;
  dQdq->noalias() += grad.transpose() * w.row3;
}

SpatialBushing::SpatialBushing(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                               const JointFrame& frameJ, const std::array<double, 6>& stiffness,
                               const std::array<double, 6>& damping)
    : Force(std::move(name), {bodyI, bodyJ}), frameI_(frameI), frameJ_(frameJ), stiffness_(stiffness),
      damping_(damping) {
  const std::string who = "force '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  checkJointFrame(frameI, who + " frame 0");
  checkJointFrame(frameJ, who + " frame 1");
  for (int k = 0; k < 6; ++k) {
    requireFinite(stiffness[k], who + ": stiffness[" + std::to_string(k) + "]");
    requireFinite(damping[k], who + ": damping[" + std::to_string(k) + "]");
    if (stiffness[k] < 0.0 || damping[k] < 0.0) throw InputError(who + ": stiffness and damping must be >= 0");
  }
}

bool SpatialBushing::isConservative() const {
  for (double c : damping_) {
    if (c != 0.0) return false;
  }
  return true;
}

double SpatialBushing::measure(int k, FramePair& pair, KinematicsWork& w, RowVecX& grad, MatX* H) const {
  if (k < 3) {
    double c = 0.0;
    pair.axisGap(k, c, grad, H);
    return c;
  }
  // rotation about axis a of frame i: (x_b^i . x_c^j - x_c^i . x_b^j) / 2, (a, b, c) cyclic
  const int a = k - 3, b = (a + 1) % 3, c = (a + 2) % 3;
  double s1 = 0.0, s2 = 0.0;
  pair.axisAxis(b, c, s1, grad, H);
  if (H) *H *= -1.0;  // accumulate -H of the second term, then flip back
  pair.axisAxis(c, b, s2, w.row5, H);
  if (H) *H *= -0.5;
  grad = 0.5 * (grad - w.row5);
  return 0.5 * (s1 - s2);
}

double SpatialBushing::potentialEnergy(const BodyStates& bodies) const {
  KinematicsWork w;
  FramePair pair(bodies, frameI_, frameJ_, false, w);
  double V = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double c = measure(k, pair, w, w.row7, nullptr);
    V += 0.5 * stiffness_[k] * c * c;
  }
  return V;
}

void SpatialBushing::addForce(double, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                              KinematicsWork& w) const {
  // per measure: f = K c + C c', c' = grad v;  Q -= f grad^T;  dQ/dv -= C grad^T grad;
  // dQ/dq -= f H + grad^T (K grad T+ + C v^T H)
  FramePair pair(bodies, frameI_, frameJ_, dQdq != nullptr, w);
  RowVecX& grad = w.row7;
  MatX& H = w.C;
  for (int k = 0; k < 6; ++k) {
    if (stiffness_[k] == 0.0 && damping_[k] == 0.0) continue;
    if (dQdq) H.setZero(pair.numVelocities(), pair.numCoordinates());
    const double c = measure(k, pair, w, grad, dQdq ? &H : nullptr);
    const double f = stiffness_[k] * c + damping_[k] * grad.dot(v);
    Q.noalias() -= f * grad.transpose();
    if (dQdv) {
      w.row6 = damping_[k] * grad;
      dQdv->noalias() -= grad.transpose() * w.row6;
    }
    if (!dQdq) continue;
    w.row3.noalias() = grad * pair.Tinv();
    w.row3 *= stiffness_[k];
    w.row4.noalias() = v.transpose() * H;
    w.row3 += damping_[k] * w.row4;
    *dQdq -= f * H;
    dQdq->noalias() -= grad.transpose() * w.row3;
  }
}

}  // namespace flexmbd
