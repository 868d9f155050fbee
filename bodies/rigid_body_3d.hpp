/// @file
/// Spatial rigid body: centre-of-mass position and Euler parameters (unit quaternion);
/// velocities are the centre of mass's velocity (world axes) and the angular velocity in
/// body axes, so the mass matrix is constant (docs/spatial.md).
#pragma once

#include "core/body.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

/// Inertial data of a spatial rigid body; the body frame has its origin at the centre of
/// mass, and points are given in it.
struct RigidBody3dProperties {
  double mass = 1.0;                   ///< kg, > 0
  Mat3 inertia = Mat3::Identity();     ///< about the centre of mass, body axes, kg m^2 (symmetric, positive definite)
};

/// Initial state of a spatial body frame (the integrator makes it consistent).
struct FrameState3d {
  Vec3 position = Vec3::Zero();            ///< of the centre of mass, world axes
  Mat3 orientation = Mat3::Identity();     ///< body axes in world axes (a rotation matrix)
  Vec3 velocity = Vec3::Zero();            ///< of the centre of mass, world axes
  Vec3 angularVelocity = Vec3::Zero();     ///< body axes
};

/// q = (x, y, z, e0, e1, e2, e3): centre of mass and Euler parameters p; v = (x', y', z',
/// wx, wy, wz), angular velocity w in body axes. A point u (body axes) is at r = R + A(p) u.
/// Kinematics q' = T(q) v with T = diag(I, 1/2 L(p)^T) (Nikravesh1988, eq. 6.41); mass
/// matrix diag(m I, J) and gyroscopic force -w x J w (Euler's equations; Nikravesh1988). The length of p
/// is a gauge (A uses p / |p|, T is tangent to the sphere |p| = const): it changes only by
/// integration error and does not enter any result; increments renormalise it.
class RigidBody3d final : public Body {
 public:
  /// @throws InputError (naming the body) for a non-positive mass, an inertia tensor that
  /// is not symmetric positive definite or violates the triangle inequality, or an
  /// orientation that is not a rotation.
  RigidBody3d(std::string name, const RigidBody3dProperties& props, const FrameState3d& initial);

  int numCoordinates() const override { return 7; }
  int numVelocities() const override { return 6; }
  std::vector<std::string> coordinateNames() const override { return {"x", "y", "z", "e0", "e1", "e2", "e3"}; }
  std::vector<std::string> velocityNames() const override {
    return {"x_dot", "y_dot", "z_dot", "wx", "wy", "wz"};
  }
  std::vector<CoordinateKind> coordinateKinds() const override;
  std::vector<CoordinateKind> velocityKinds() const override;
  VecX initialCoordinates() const override;
  VecX initialVelocities() const override;
  double mass() const override { return props_.mass; }
  const Mat3& inertia() const { return props_.inertia; }

  bool velocitiesAreCoordinateRates() const override { return false; }
  void addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const override;
  void addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const override;
  void addCoordinateRate(const ConstVecRef& q, const ConstVecRef& w, Eigen::Ref<VecX> out) const override;
  void addCoordinateRateJacobian(const ConstVecRef& q, const ConstVecRef& w, const MatrixSink& K) const override;
  void applyIncrement(const ConstVecRef& q, const ConstVecRef& dv, Eigen::Ref<VecX> out) const override;
  std::vector<int> coordinatesOfVelocities(const std::vector<int>& vcols) const override;

  void addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const override;
  void addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const override;
  void addMassMatrixDerivative(const ConstVecRef&, const ConstVecRef&, const MatrixSink&) const override {}
  void addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const override;
  void addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                 const MatrixSink& dQdv) const override;
  void addGravityForce(const ConstVecRef& q, const Vec3& g, VecX& Q) const override;
  void addGravityJacobian(const ConstVecRef&, const Vec3&, const MatrixSink&) const override {}
  double gravityPotential(const ConstVecRef& q, const Vec3& g) const override;
  using Body::pointKinematics;
  /// @throws InputError: a spatial body has no planar point kinematics.
  void pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                       bool withHessians,
                       PointKinematics& out) const override;
  void frameKinematics(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                       const std::vector<int>* qcols, FrameKinematics& out) const override;
  void addFrameCurvature(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                         const std::vector<int>* qcols, const Vec3& wr, const Vec3& ww,
                         Eigen::Ref<MatX> out) const override;
  Vec3 centreOfMass(const ConstVecRef& q) const override { return q.head<3>(); }
  /// A(p / |p|) at q.
  static Mat3 rotationOf(const ConstVecRef& q) { return quaternionRotation(q.segment<4>(3)); }

 private:
  RigidBody3dProperties props_;
  FrameState3d initial_;
};

}  // namespace flexmbd
