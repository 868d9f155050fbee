#include "bodies/rigid_body_3d.hpp"

#include "bodies/euler_frame_rates.hpp"

#include <Eigen/Eigenvalues>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

/// Selects the used columns of a full row block (cols null: all).
template <class Full, class Out>
void selectColumns(const Full& full, const std::vector<int>* cols, Out& out) {
  if (!cols) {
    out = full;
    return;
  }
  out.resize(full.rows(), static_cast<Eigen::Index>(cols->size()));
  for (size_t k = 0; k < cols->size(); ++k) out.col(k) = full.col((*cols)[k]);
}

}  // namespace

RigidBody3d::RigidBody3d(std::string name, const RigidBody3dProperties& props, const FrameState3d& initial)
    : Body(std::move(name)), props_(props), initial_(initial) {
  const std::string who = "body '" + this->name() + "'";
  requirePositive(props.mass, who + ": mass");
  const Mat3& J = props.inertia;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) requireFinite(J(i, j), who + ": inertia[" + std::to_string(i) + "][" + std::to_string(j) + "]");
  }
  if (!((J - J.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * J.cwiseAbs().maxCoeff())) {
    throw InputError(who + ": inertia: the tensor must be symmetric");
  }
  const Eigen::Vector3d I = Eigen::SelfAdjointEigenSolver<Mat3>(J).eigenvalues();
  if (!(I[0] > 0.0)) throw InputError(who + ": inertia: the tensor must be positive definite (principal moments > 0)");
  // principal moments of a real body satisfy the triangle inequality I_a + I_b >= I_c
  if (I[0] + I[1] < I[2] * (1.0 - 1e-12)) {
    throw InputError(who + ": inertia: principal moments " + std::to_string(I[0]) + ", " + std::to_string(I[1]) +
                     ", " + std::to_string(I[2]) + " violate I1 + I2 >= I3 (no mass distribution has them)");
  }
  for (int k = 0; k < 3; ++k) {
    requireFinite(initial.position[k], who + ": position[" + std::to_string(k) + "]");
    requireFinite(initial.velocity[k], who + ": velocity[" + std::to_string(k) + "]");
    requireFinite(initial.angularVelocity[k], who + ": angular_velocity[" + std::to_string(k) + "]");
  }
  const Mat3& R = initial.orientation;
  if (!R.allFinite() || !((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) ||
      !(R.determinant() > 0.0)) {
    throw InputError(who + ": orientation: not a rotation matrix (expected orthonormal columns, determinant +1)");
  }
}

std::vector<CoordinateKind> RigidBody3d::coordinateKinds() const {
  using K = CoordinateKind;
  return {K::Position, K::Position, K::Position, K::Angle, K::Angle, K::Angle, K::Angle};
}

std::vector<CoordinateKind> RigidBody3d::velocityKinds() const {
  using K = CoordinateKind;
  return {K::Position, K::Position, K::Position, K::Angle, K::Angle, K::Angle};
}

VecX RigidBody3d::initialCoordinates() const {
  VecX q(7);
  q.head<3>() = initial_.position;
  q.segment<4>(3) = quaternionFromRotation(initial_.orientation);
  return q;
}

VecX RigidBody3d::initialVelocities() const {
  VecX v(6);
  v << initial_.velocity, initial_.angularVelocity;
  return v;
}

void RigidBody3d::addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const {
  addEulerFrameRateMatrix(q, 0, T);
}

void RigidBody3d::addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const {
  addEulerFrameRateInverse(q, 0, Tinv);
}

void RigidBody3d::addCoordinateRate(const ConstVecRef& q, const ConstVecRef& w, Eigen::Ref<VecX> out) const {
  out.head<3>() += w.head<3>();
  // p' = 1/2 L^T w (Nikravesh1988, eq. 6.41)
  out.segment<4>(3) += 0.5 * quaternionL(q.segment<4>(3)).transpose() * w.tail<3>();
}

void RigidBody3d::addCoordinateRateJacobian(const ConstVecRef&, const ConstVecRef& w, const MatrixSink& K) const {
  K.addBlock(3, 3, 0.5 * quaternionLTransposeJacobian(w.tail<3>()));
}

void RigidBody3d::applyIncrement(const ConstVecRef& q, const ConstVecRef& dv, Eigen::Ref<VecX> out) const {
  // r + dr;  p (x) exp(dpi / 2): the body-axes rotation dpi applied after A(p), then |p| = 1
  out.head<3>() = q.head<3>() + dv.head<3>();
  const Vec3 dpi = dv.tail<3>();
  const double angle = dpi.norm();
  const Vec4 dp = angle > 0.0 ? quaternionFromAxisAngle(dpi / angle, angle) : Vec4(1.0, 0.0, 0.0, 0.0);
  out.segment<4>(3) = quaternionProduct(q.segment<4>(3), dp).normalized();
}

std::vector<int> RigidBody3d::coordinatesOfVelocities(const std::vector<int>& vcols) const {
  std::vector<int> q;
  bool rotation = false;
  for (int c : vcols) {
    if (c < 3) {
      q.push_back(c);
    } else {
      rotation = true;
    }
  }
  if (rotation) {
    for (int c = 3; c < 7; ++c) q.push_back(c);
  }
  return q;
}

void RigidBody3d::addMassMatrix(const ConstVecRef&, const MatrixSink& M) const {
  for (int k = 0; k < 3; ++k) M.add(k, k, props_.mass);
  M.addBlock(3, 3, props_.inertia);
}

void RigidBody3d::addMassTimes(const ConstVecRef&, const ConstVecRef& a, Eigen::Ref<VecX> out) const {
  out.head<3>() += props_.mass * a.head<3>();
  out.tail<3>() += props_.inertia * a.tail<3>();
}

void RigidBody3d::addInternalForces(const ConstVecRef&, const ConstVecRef& v, VecX& Q) const {
  const Vec3 w = v.tail<3>();
  Q.tail<3>() -= w.cross(props_.inertia * w);  // Euler's equations: J w' + w x J w = torque (Nikravesh1988)
}

void RigidBody3d::addInternalForceJacobians(const ConstVecRef&, const ConstVecRef& v, const MatrixSink&,
                                            const MatrixSink& dQdv) const {
  const Vec3 w = v.tail<3>();
  // d(-w x J w)/dw = -(w~ J - (J w)~)
  dQdv.addBlock(3, 3, -(skew(w) * props_.inertia - skew(props_.inertia * w)));
}

void RigidBody3d::addGravityForce(const ConstVecRef&, const Vec3& g, VecX& Q) const {
  Q.head<3>() += props_.mass * g;
}

double RigidBody3d::gravityPotential(const ConstVecRef& q, const Vec3& g) const {
  return -props_.mass * g.dot(q.head<3>());
}

void RigidBody3d::pointKinematics(const ConstVecRef&, const Vec2&, int, const std::vector<int>*, bool,
                                  PointKinematics&) const {
  throw InputError("body '" + name() + "' is spatial: planar joints and forces need planar bodies");
}

void RigidBody3d::frameKinematics(const ConstVecRef& q, const Vec3& point, int, const std::vector<int>* cols,
                                  const std::vector<int>* qcols, FrameKinematics& out) const {
  // r = R + A u;  r' = R' - A u~ w;  omega = A w  (w in body axes; Nikravesh1988)
  const Mat3 A = rotationOf(q);
  out.A = A;
  out.r = q.head<3>() + A * point;
  Eigen::Matrix<double, 3, 6> Jr, Jw;
  Jr << Mat3::Identity(), -A * skew(point);
  Jw << Mat3::Zero(), A;
  selectColumns(Jr, cols, out.Jr);
  selectColumns(Jw, cols, out.Jw);
  Eigen::Matrix<double, 6, 7> Tinv = Eigen::Matrix<double, 6, 7>::Zero();
  Tinv.topLeftCorner<3, 3>().setIdentity();
  Tinv.bottomRightCorner<3, 4>() = eulerRateInverse(q);
  if (!cols && !qcols) {
    out.Tinv = Tinv;
    return;
  }
  const int nv = cols ? static_cast<int>(cols->size()) : 6, nq = qcols ? static_cast<int>(qcols->size()) : 7;
  out.Tinv.resize(nv, nq);
  for (int i = 0; i < nv; ++i) {
    for (int j = 0; j < nq; ++j) out.Tinv(i, j) = Tinv(cols ? (*cols)[i] : i, qcols ? (*qcols)[j] : j);
  }
}

void RigidBody3d::addFrameCurvature(const ConstVecRef& q, const Vec3& point, int, const std::vector<int>* cols,
                                    const std::vector<int>* qcols, const Vec3& wr, const Vec3& ww,
                                    Eigen::Ref<MatX> out) const {
  // Jr^T wr + Jw^T ww = [wr; u~ A^T wr + A^T ww]; d(A^T c)/dpi = (A^T c)~ for a body-axes
  // rotation dpi, and dpi = T+ dp: the rotation rows' derivative is (u~ (A^T wr)~ + (A^T ww)~) T+.
  const Mat3 A = rotationOf(q);
  const Eigen::Matrix<double, 3, 4> block =
      (skew(point) * skew(A.transpose() * wr) + skew(A.transpose() * ww)) * eulerRateInverse(q);
  const int nv = cols ? static_cast<int>(cols->size()) : 6, nq = qcols ? static_cast<int>(qcols->size()) : 7;
  for (int i = 0; i < nv; ++i) {
    const int vi = cols ? (*cols)[i] : i;
    if (vi < 3) continue;
    for (int j = 0; j < nq; ++j) {
      const int qj = qcols ? (*qcols)[j] : j;
      if (qj >= 3) out(i, j) += block(vi - 3, qj - 3);
    }
  }
}

}  // namespace flexmbd
