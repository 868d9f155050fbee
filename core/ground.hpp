/// @file
/// The ground: a body without coordinates; its points are fixed in the world frame. Part of
/// the core: every System makes it as body 0 (kGround) in its constructor.
#pragma once

#include "core/body.hpp"

namespace flexmbd {

class Ground final : public Body {
 public:
  Ground() : Body("ground") {}
  int numCoordinates() const override { return 0; }
  std::vector<std::string> coordinateNames() const override { return {}; }
  VecX initialCoordinates() const override { return VecX(0); }
  VecX initialVelocities() const override { return VecX(0); }
  double mass() const override { return 0.0; }
  void addMassMatrix(const ConstVecRef&, const MatrixSink&) const override {}
  void addMassTimes(const ConstVecRef&, const ConstVecRef&, Eigen::Ref<VecX>) const override {}
  void addMassMatrixDerivative(const ConstVecRef&, const ConstVecRef&, const MatrixSink&) const override {}
  void addInternalForces(const ConstVecRef&, const ConstVecRef&, VecX&) const override {}
  void addInternalForceJacobians(const ConstVecRef&, const ConstVecRef&, const MatrixSink&,
                                 const MatrixSink&) const override {}
  void addGravityForce(const ConstVecRef&, const Vec3&, VecX&) const override {}
  void addGravityJacobian(const ConstVecRef&, const Vec3&, const MatrixSink&) const override {}
  double gravityPotential(const ConstVecRef&, const Vec3&) const override { return 0.0; }
  using Body::pointKinematics;
  void pointKinematics(const ConstVecRef&, const Vec2& point, int, const std::vector<int>*, bool withHessians,
                       PointKinematics& out) const override {
    out.r = point;
    out.phi = 0.0;
    out.reset(0, withHessians);
  }
  void frameKinematics(const ConstVecRef&, const Vec3& point, int, const std::vector<int>*, const std::vector<int>*,
                       FrameKinematics& out) const override {
    out.r = point;
    out.A.setIdentity();
    out.Jr.resize(3, 0);
    out.Jw.resize(3, 0);
    out.Tinv.resize(0, 0);
  }
  void addFrameCurvature(const ConstVecRef&, const Vec3&, int, const std::vector<int>*, const std::vector<int>*,
                         const Vec3&, const Vec3&, Eigen::Ref<MatX>) const override {}
  Vec3 centreOfMass(const ConstVecRef&) const override { return Vec3::Zero(); }
};

}  // namespace flexmbd
