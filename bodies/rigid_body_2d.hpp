/// @file
/// Planar rigid body described by its frame: position (x, y) and angle theta.
#pragma once

#include "core/body.hpp"

namespace flexmbd {

/// Inertial data of a planar rigid body.
struct RigidBodyProperties {
  double mass = 1.0;               ///< kg, > 0
  double inertia = 1.0;            ///< about the centre of mass, kg m^2, > 0
  Vec2 com = Vec2::Zero();         ///< centre of mass in the body frame
};

/// Initial state of a planar frame (the integrator makes it consistent).
struct FrameState2d {
  Vec2 position = Vec2::Zero();
  double angle = 0.0;
  Vec2 velocity = Vec2::Zero();    ///< of the frame origin, world axes
  double angularVelocity = 0.0;
};

/// Coordinates q = (x, y, theta) of the body frame; a point u (body frame) is at
/// r = R + A(theta) u. With the centre of mass c off the frame origin the mass matrix
/// couples translation and rotation (Shabana2005, ch. 5):
///   M = [ m I        m S A c        ]
///       [ sym.   J + m c^T c        ]
class RigidBody2d final : public Body {
 public:
  /// @throws InputError (naming the body) if mass or inertia is not positive/finite.
  RigidBody2d(std::string name, const RigidBodyProperties& props, const FrameState2d& initial);

  int numCoordinates() const override { return 3; }
  std::vector<std::string> coordinateNames() const override { return {"x", "y", "theta"}; }
  std::vector<CoordinateKind> coordinateKinds() const override {
    return {CoordinateKind::Position, CoordinateKind::Position, CoordinateKind::Angle};
  }
  VecX initialCoordinates() const override;
  VecX initialVelocities() const override;
  double mass() const override { return props_.mass; }
  double inertia() const { return props_.inertia; }
  const Vec2& com() const { return props_.com; }

  void addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const override;
  void addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const override;
  void addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a,
                               const MatrixSink& K) const override;
  void addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const override;
  void addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                 const MatrixSink& dQdv) const override;
  void addGravityForce(const ConstVecRef& q, const Vec3& g, VecX& Q) const override;
  void addGravityJacobian(const ConstVecRef& q, const Vec3& g, const MatrixSink& K) const override;
  double gravityPotential(const ConstVecRef& q, const Vec3& g) const override;
  using Body::pointKinematics;
  void pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                       bool withHessians,
                       PointKinematics& out) const override;
  Vec3 centreOfMass(const ConstVecRef& q) const override;
  /// The centre of mass in the plane.
  Vec2 planarCentreOfMass(const ConstVecRef& q) const;

 private:
  RigidBodyProperties props_;
  FrameState2d initial_;
};

}  // namespace flexmbd
