#include "forces/applied_load.hpp"

#include "core/errors.hpp"

namespace flexmbd {

AppliedLoad::AppliedLoad(std::string name, BodyIndex body, const Vec2& point, TimeLawPtr forceX,
                         TimeLawPtr forceY, TimeLawPtr torque)
    : Force(std::move(name), {body}),
      point_(point),
      forceX_(std::move(forceX)),
      forceY_(std::move(forceY)),
      torque_(std::move(torque)) {
  requireFinite(point.x(), "force '" + this->name() + "': point[0]");
  requireFinite(point.y(), "force '" + this->name() + "': point[1]");
}

void AppliedLoad::addForce(double t, const std::vector<BodyState>& b, const VecX&, VecX& Q,
                           MatX* dQdq, MatX*) const {
  const PointKinematics p = b[0].point(point_, dQdq != nullptr);
  const Vec2 F(forceX_ ? forceX_->evaluate(t).f : 0.0, forceY_ ? forceY_->evaluate(t).f : 0.0);
  const double tau = torque_ ? torque_->evaluate(t).f : 0.0;
  Q += p.Jr.transpose() * F + tau * p.Jphi.transpose();
  if (dQdq) *dQdq += p.hessianR(F) + tau * p.Hphi;
}

}  // namespace flexmbd
