/// @file
/// Force elements of spatial models: a prescribed force and torque at a body point, and a
/// translational spring-damper between two body points.
#pragma once

#include "core/force.hpp"
#include <array>

#include "core/time_law.hpp"
#include "core/user_function.hpp"
#include "joints/frame_pair.hpp"

namespace flexmbd {

/// Q = Jr^T F(t) + Jw^T M(t) (virtual work, Haug1989): force F at the body point and torque M, world axes; absent
/// laws count as zero. dQ/dq is the point's curvature term with weights (F, M).
class SpatialAppliedLoad final : public Force {
 public:
  /// laws: force x, y, z, torque x, y, z (null: zero); at least one given.
  SpatialAppliedLoad(std::string name, BodyIndex body, const Vec3& point, std::array<TimeLawPtr, 6> laws);
  std::string typeName() const override { return "applied_load"; }
  std::vector<Attachment> attachments() const override { return {{bodies()[0], point_}}; }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  bool isConservative() const override { return false; }

 private:
  Vec3 point_;
  std::array<TimeLawPtr, 6> laws_;
};

/// Tension f = k (l - l0) + c l' along the line of two body points, l = |r_j - r_i|:
/// Q = -f grad(l)^T (Shabana2005, ch. 7, in velocity form).
/// With a user law (core/user_function.hpp), f = law(t, l, l') instead (no potential).
class SpatialSpringDamper final : public Force {
 public:
  SpatialSpringDamper(std::string name, BodyIndex bodyI, const Vec3& pointI, BodyIndex bodyJ, const Vec3& pointJ,
                      double stiffness, double damping, double freeLength, SpringLawPtr law = nullptr);
  std::string typeName() const override { return "spring_damper"; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], pointI_}, {bodies()[1], pointJ_}};
  }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  double potentialEnergy(const BodyStates& bodies) const override;
  bool isConservative() const override { return damping_ == 0.0 && !law_; }
  bool dependsOnTime() const override { return law_ != nullptr; }
  /// The current length l.
  double length(const BodyStates& bodies) const;

 private:
  Vec3 pointI_, pointJ_;
  double stiffness_, damping_, freeLength_;
  SpringLawPtr law_;
};

/// Torque -k (theta - theta0) - c theta' about a spatial revolute or cylindrical joint's
/// axis, theta the joint angle of SpatialJointAngleDriver (frame j's x axis from frame i's,
/// about frame i's z axis), taken within half a turn of theta0: Q = tau grad(theta)^T (Haug1989).
/// With a user law (core/user_function.hpp), tau = -law(t, theta, theta') instead, theta
/// within half a turn of theta0 (no potential).
class SpatialRotationalSpringDamper final : public Force {
 public:
  SpatialRotationalSpringDamper(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                                const JointFrame& frameJ, double stiffness, double damping, double freeAngle,
                                SpringLawPtr law = nullptr);
  std::string typeName() const override { return "rotational_spring_damper"; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], frameI_.point}, {bodies()[1], frameJ_.point}};
  }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  double potentialEnergy(const BodyStates& bodies) const override;
  bool isConservative() const override { return damping_ == 0.0 && !law_; }
  bool dependsOnTime() const override { return law_ != nullptr; }

 private:
  JointFrame frameI_, frameJ_;
  double stiffness_, damping_, freeAngle_;
  SpringLawPtr law_;
};

/// Six-component bushing between frame i (body i) and frame j (body j): the measures
///   c = (x_i . d, y_i . d, z_i . d,                         (d = r_j - r_i: translations in frame i)
///        (y_i . z_j - z_i . y_j) / 2, (z_i . x_j - x_i . z_j) / 2, (x_i . y_j - y_i . x_j) / 2)
/// (the last three: the relative rotation about x_i, y_i, z_i, exact to second order in
/// the angles) with generalised force Q = -sum_k (K_k c_k + C_k c_k') grad(c_k)^T. For the
/// small relative motions of an elastic mount; its energy is 1/2 sum_k K_k c_k^2.
class SpatialBushing final : public Force {
 public:
  SpatialBushing(std::string name, BodyIndex bodyI, const JointFrame& frameI, BodyIndex bodyJ,
                 const JointFrame& frameJ, const std::array<double, 6>& stiffness, const std::array<double, 6>& damping);
  std::string typeName() const override { return "bushing"; }
  std::vector<Attachment> attachments() const override {
    return {{bodies()[0], frameI_.point}, {bodies()[1], frameJ_.point}};
  }
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                KinematicsWork& work) const override;
  using Force::addForce;
  double potentialEnergy(const BodyStates& bodies) const override;
  bool isConservative() const override;
  bool dependsOnTime() const override { return false; }

 private:
  /// c_k with its gradient into `grad` and, if H, its d(grad^T)/dq into *H (work rows used).
  double measure(int k, FramePair& pair, KinematicsWork& w, RowVecX& grad, MatX* H) const;
  JointFrame frameI_, frameJ_;
  std::array<double, 6> stiffness_, damping_;
};

}  // namespace flexmbd
