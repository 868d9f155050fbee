#include "bodies/rigid_body_2d.hpp"

#include "core/errors.hpp"

namespace flexmbd {

RigidBody2d::RigidBody2d(std::string name, const RigidBodyProperties& props,
                         const FrameState2d& initial)
    : Body(std::move(name)), props_(props), initial_(initial) {
  const std::string who = "body '" + this->name() + "'";
  requirePositive(props.mass, who + ": mass");
  requirePositive(props.inertia, who + ": inertia");
  requireFinite(props.com.x(), who + ": com[0]");
  requireFinite(props.com.y(), who + ": com[1]");
  requireFinite(initial.position.x(), who + ": position[0]");
  requireFinite(initial.position.y(), who + ": position[1]");
  requireFinite(initial.angle, who + ": angle");
  requireFinite(initial.velocity.x(), who + ": velocity[0]");
  requireFinite(initial.velocity.y(), who + ": velocity[1]");
  requireFinite(initial.angularVelocity, who + ": angular_velocity");
}

VecX RigidBody2d::initialCoordinates() const {
  return Eigen::Vector3d(initial_.position.x(), initial_.position.y(), initial_.angle);
}

VecX RigidBody2d::initialVelocities() const {
  return Eigen::Vector3d(initial_.velocity.x(), initial_.velocity.y(), initial_.angularVelocity);
}

/// The 3 x 3 mass matrix of the frame coordinates (x, y, theta) with the COM offset c.
static Eigen::Matrix3d rigidMassMatrix(const RigidBodyProperties& props, double theta) {
  const double m = props.mass;
  const Vec2 sac = perp(rotation(theta) * props.com);  // S A c = dA/dtheta c
  Eigen::Matrix3d M;
  M << m, 0.0, m * sac.x(),                           //
      0.0, m, m * sac.y(),                            //
      m * sac.x(), m * sac.y(), props.inertia + m * props.com.squaredNorm();
  return M;
}

void RigidBody2d::addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const {
  M.addBlock(0, 0, rigidMassMatrix(props_, q[2]));
}

void RigidBody2d::addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const {
  out += rigidMassMatrix(props_, q[2]) * a;
}

void RigidBody2d::addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a,
                                          const MatrixSink& K) const {
  // d(S A c)/dtheta = S S A c = -A c
  const double m = props_.mass;
  const Vec2 ac = rotation(q[2]) * props_.com;
  K.add(0, 2, -m * ac.x() * a[2]);
  K.add(1, 2, -m * ac.y() * a[2]);
  K.add(2, 2, -m * ac.dot(a.head<2>()));
}

void RigidBody2d::addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const {
  // Quadratic velocity vector: Q_R = m A c thetadot^2, Q_theta = 0 (Lagrange's equations
  // of T = 1/2 m |Rdot + S A c thetadot|^2 + 1/2 J thetadot^2; Shabana2005, ch. 5).
  const Vec2 ac = rotation(q[2]) * props_.com;
  Q.head<2>() += props_.mass * ac * v[2] * v[2];
}

void RigidBody2d::addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v,
                                            const MatrixSink& dQdq, const MatrixSink& dQdv) const {
  const Vec2 ac = rotation(q[2]) * props_.com;
  const double m = props_.mass;
  dQdq.addBlock(0, 2, m * perp(ac) * v[2] * v[2]);
  dQdv.addBlock(0, 2, 2.0 * m * ac * v[2]);
}

void RigidBody2d::addGravityForce(const ConstVecRef& q, const Vec3& g3, VecX& Q) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  const double m = props_.mass;
  Q.head<2>() += m * g;
  Q[2] += m * perp(rotation(q[2]) * props_.com).dot(g);
}

void RigidBody2d::addGravityJacobian(const ConstVecRef& q, const Vec3& g3, const MatrixSink& K) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  K.add(2, 2, -props_.mass * (rotation(q[2]) * props_.com).dot(g));
}

double RigidBody2d::gravityPotential(const ConstVecRef& q, const Vec3& g3) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  return -props_.mass * g.dot(planarCentreOfMass(q));
}

void RigidBody2d::pointKinematics(const ConstVecRef& q, const Vec2& point, int, const std::vector<int>* cols,
                                  bool withHessians, PointKinematics& p) const {
  // r = R + A u;  dr/dtheta = S A u;  d2r/dtheta2 = -A u;  phi = theta (Nikravesh1988).
  const Vec2 au = rotation(q[2]) * point;
  const int n = cols ? static_cast<int>(cols->size()) : 3;
  p.r = q.head<2>() + au;
  p.phi = q[2];
  p.reset(n, withHessians);
  for (int a = 0; a < n; ++a) {
    const int c = cols ? (*cols)[a] : a;
    if (c < 2) {
      p.Jr(c, a) = 1.0;
      continue;
    }
    p.Jr.col(a) = perp(au);
    p.Jphi[a] = 1.0;
    if (!withHessians) continue;
    p.Hrx(a, a) = -au.x();
    p.Hry(a, a) = -au.y();
  }
}

Vec3 RigidBody2d::centreOfMass(const ConstVecRef& q) const { return lift(planarCentreOfMass(q)); }

Vec2 RigidBody2d::planarCentreOfMass(const ConstVecRef& q) const {
  return q.head<2>() + rotation(q[2]) * props_.com;
}

}  // namespace flexmbd
