#include "forces/applied_load.hpp"

#include "core/errors.hpp"
#include "core/user_function.hpp"

namespace flexmbd {

void requireLoadableBody(BodyIndex body, const std::string& who) {
  if (body == kGround) {
    throw InputError(who + ": a load on the ground does nothing (the ground does not move; expected a body of the "
                           "model)");
  }
}

AppliedLoad::AppliedLoad(std::string name, BodyIndex body, const Vec2& point, TimeLawPtr forceX,
                         TimeLawPtr forceY, TimeLawPtr torque)
    : Force(std::move(name), {body}),
      point_(point),
      forceX_(std::move(forceX)),
      forceY_(std::move(forceY)),
      torque_(std::move(torque)) {
  requireLoadableBody(body, "force '" + this->name() + "'");
  requireFinite(point.x(), "force '" + this->name() + "': point[0]");
  requireFinite(point.y(), "force '" + this->name() + "': point[1]");
}

void AppliedLoad::addForce(double t, const BodyStates& b, const VecX&, VecX& Q, MatX* dQdq, MatX*,
                           KinematicsWork& w) const {
  // Q = Jr^T F + tau Jphi^T (virtual work of a force F at the point and a torque tau; Haug1989)
  b[0].point(point_, b.pointId(0), dQdq != nullptr, w.pi);
  const PointKinematics& p = w.pi;
  Vec2 F = Vec2::Zero();
  double tau = 0.0;
  try {
    if (forceX_) F.x() = forceX_->value(t);
    if (forceY_) F.y() = forceY_->value(t);
    if (torque_) tau = torque_->value(t);
  } catch (const UserFunctionError& e) {  // a user law raised: name the force
    rethrowWithOwner(e, "force '" + name() + "'");
  }
  Q.noalias() += p.Jr.transpose() * F;
  Q += tau * p.Jphi.transpose();
  if (dQdq) *dQdq += F.x() * p.Hrx + F.y() * p.Hry + tau * p.Hphi;
}

}  // namespace flexmbd
