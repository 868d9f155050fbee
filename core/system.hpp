/// @file
/// The multibody system model: bodies, constraints (joints and drivers) and forces are
/// added, then finalize() freezes the model and builds the index maps.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/body.hpp"
#include "core/constraint.hpp"
#include "core/force.hpp"
#include "core/time_law.hpp"

namespace flexmbd {

/// A multibody system, planar or spatial: its bodies (rigid and flexible, planar and
/// spatial bodies in one model), constraints (joints and drivers) and force elements,
/// with gravity. Build phase: add*; then finalize(); afterwards the model is immutable
/// and add* throws InputError. Body 0 is the ground ("ground"). Movable, not copyable.
/// Integrated by simulate() (simulation/simulation.hpp); read from a scene file by
/// loadScene() (scene/scene.hpp); built in code with the free functions of
/// builders/planar_builders.hpp and builders/spatial_builders.hpp.
class System {
 public:
  /// An empty system with its ground body (kGround).
  System();
  ~System();
  System(System&&) noexcept;             ///< Moves the model (built or finalized).
  System& operator=(System&&) noexcept;  ///< Moves the model (built or finalized).

  // ----- build phase -------------------------------------------------------------
  /// Adds a body (the system owns it): its index. @throws InputError after finalize()
  /// or if its name is taken.
  BodyIndex addBody(std::unique_ptr<Body> body);
  /// Adds a joint or driver on bodies added before: its index. @throws InputError after
  /// finalize(), for a taken name or an unknown body.
  ConstraintIndex addConstraint(std::unique_ptr<Constraint> constraint);
  /// Adds a force element on bodies added before: its index. @throws InputError as
  /// addConstraint().
  ForceIndex addForce(std::unique_ptr<Force> force);
  /// Acceleration of gravity (world axes), default zero; a planar one lies in the x-y plane.
  void setGravity(const Vec3& g);
  void setGravity(const Vec2& g) { setGravity(lift(g)); }  ///< Planar gravity (z = 0).

  // The convenience builders of concrete bodies, joints and forces (addRigidBody(sys, ...),
  // addRevoluteJoint(sys, ...), ...) are free functions: builders/planar_builders.hpp.

  /// Freezes the model: index maps, checks of attachment points and names.
  void finalize();
  bool isFinalized() const { return finalized_; }  ///< True after finalize().

  // ----- queries (any time) ------------------------------------------------------
  /// Number of bodies, the ground included.
  int numBodies() const { return static_cast<int>(bodies_.size()); }
  int numConstraints() const { return static_cast<int>(constraints_.size()); }  ///< Joints and drivers.
  int numForces() const { return static_cast<int>(forces_.size()); }  ///< Force elements.
  /// Body, constraint or force by index. @throws std::out_of_range for an index not given
  /// by this system.
  const Body& body(BodyIndex i) const { return *bodies_.at(i.value); }
  const Constraint& constraint(ConstraintIndex i) const { return *constraints_.at(i.value); }  ///< @copydoc body
  const Force& force(ForceIndex i) const { return *forces_.at(i.value); }  ///< @copydoc body
  const Vec3& gravity() const { return gravity_; }  ///< Acceleration of gravity (world axes).
  /// @throws InputError listing the known bodies if there is none of that name.
  BodyIndex findBody(const std::string& name) const;
  /// @throws InputError listing the known constraints if there is none of that name.
  ConstraintIndex findConstraint(const std::string& name) const;

  // ----- after finalize ----------------------------------------------------------
  // The coordinate map: body b's coordinates are q[coordinateOffset(b) .. + nq_b) and its
  // velocities v[velocityOffset(b) .. + nv_b), with q' = T_b(q_b) v_b (Body::coordinateRateMatrix).
  int numCoordinates() const { return nq_; }  ///< nq: all bodies' coordinates.
  int numVelocities() const { return nv_; }  ///< nv: all bodies' velocities (= nq for planar models).
  int numConstraintEquations() const { return m_; }  ///< m: all constraints' equations.
  /// Index of body i's first coordinate in q (results column order).
  int coordinateOffset(BodyIndex i) const { return bodyOffset_.at(i.value); }
  /// Index of body i's first velocity in v.
  int velocityOffset(BodyIndex i) const { return bodyVelocityOffset_.at(i.value); }
  /// Body b's numbers of coordinates and velocities (cached at finalize: no virtual call).
  int numCoordinates(BodyIndex i) const { return bodyNq_[i.value]; }
  int numVelocities(BodyIndex i) const { return bodyNv_[i.value]; }  ///< @copydoc numCoordinates(BodyIndex) const
  /// Constraint::equationPeriod() of each constraint, cached at finalize.
  double constraintPeriod(ConstraintIndex i) const { return constraintPeriod_[i.value]; }
  /// Constraint::isDriver() of each constraint, cached at finalize (a joint's f(t) is zero).
  bool constraintIsDriver(ConstraintIndex i) const { return constraintIsDriver_[i.value]; }
  /// Index of constraint i's first equation in g (and of its multipliers in lambda).
  int constraintOffset(ConstraintIndex i) const { return constraintOffset_.at(i.value); }
  /// True when every body has q' = v (T = I; planar models): nq == nv and the maps agree.
  bool velocitiesAreCoordinateRates() const { return coordinateRates_; }
  ///@{
  /// Global velocity index of each local velocity of a constraint / force (the columns of
  /// its G, the rows of its Q): what it uses of each of its bodies (Constraint::coordinatesUsed).
  const std::vector<int>& constraintColumns(ConstraintIndex i) const { return constraintCols_.at(i.value); }
  const std::vector<int>& forceColumns(ForceIndex i) const { return forceCols_.at(i.value); }
  ///@}
  ///@{
  /// Global coordinate index of each local coordinate of a constraint / force (the columns
  /// of its d/dq blocks); equal to the velocity columns when T = I.
  const std::vector<int>& constraintCoordinateColumns(ConstraintIndex i) const {
    return constraintQCols_.at(i.value);
  }
  const std::vector<int>& forceCoordinateColumns(ForceIndex i) const { return forceQCols_.at(i.value); }
  ///@}
  ///@{
  /// Coordinates (nq) and velocities (nv) given at construction, stacked.
  VecX initialCoordinates() const;
  VecX initialVelocities() const;
  ///@}
  /// q (+) dv body by body (Body::applyIncrement): velocity-space corrections of positions.
  VecX applyIncrement(const VecX& q, const VecX& dv) const;
  /// T(q) v body by body (nq).
  VecX coordinateRates(const VecX& q, const VecX& v) const;
  ///@{
  /// Views of a constraint's / force's bodies at the global coordinates q (size nq),
  /// restricted to the coordinates it uses.
  BodyStates constraintStates(ConstraintIndex i, const double* q) const;
  BodyStates forceStates(ForceIndex i, const double* q) const;
  ///@}
  /// "joint 'O2' (revolute, equation 1)": the constraint that owns global equation `row`.
  std::string describeEquation(int row) const;
  ///@{
  /// Global indices of the frame (reference-motion) coordinates / velocities; the others
  /// are elastic.
  std::vector<int> frameCoordinates() const;
  std::vector<int> frameVelocities() const;
  ///@}
  ///@{
  /// The kind of every coordinate / velocity, in order.
  std::vector<CoordinateKind> coordinateKinds() const;
  std::vector<CoordinateKind> velocityKinds() const;
  ///@}
  /// A length characteristic of the model: the largest distance of a body's initial
  /// position or of an attachment point (body axes) from the origin; 1 if all are zero.
  double characteristicLength() const;
  /// "crank.x", ... for every coordinate, in order.
  std::vector<std::string> coordinateNames() const;
  /// "crank.x_dot", ... for every velocity, in order (Body::velocityNames).
  std::vector<std::string> velocityNames() const;
  /// The accelerations' names: a velocity "x_dot" gives "x_ddot", any other "w" gives "w_dot".
  std::vector<std::string> accelerationNames() const;

 private:
  /// Refuses masses or rigid rotational inertias more than kMaxMagnitudeRatio apart
  /// (core/magnitude_checks.hpp) when the model is finalized.
  void checkInertiaSpread() const;
  void requireBuildPhase(const std::string& what) const;
  void requireFinalized(const char* what) const;
  void checkNewName(const std::string& name, const std::string& kind) const;
  void checkBody(BodyIndex i, const std::string& user) const;

  std::vector<std::unique_ptr<Body>> bodies_;
  std::vector<std::unique_ptr<Constraint>> constraints_;
  std::vector<std::unique_ptr<Force>> forces_;
  Vec3 gravity_ = Vec3::Zero();
  bool finalized_ = false;
  int nq_ = 0, nv_ = 0, m_ = 0;
  bool coordinateRates_ = true;
  std::vector<int> bodyOffset_, bodyVelocityOffset_, bodyNq_, bodyNv_, constraintOffset_;
  std::vector<double> constraintPeriod_;
  std::vector<char> constraintIsDriver_;
  std::vector<std::vector<int>> constraintCols_, forceCols_, constraintQCols_, forceQCols_;
  // per constraint / force, per body slot: the body-local velocities / coordinates used
  std::vector<std::vector<std::vector<int>>> constraintUsed_, forceUsed_, constraintUsedQ_, forceUsedQ_;
  /// Per element, the bodies' identifiers of its attachments (Body::resolvePoint).
  std::vector<std::vector<int>> constraintPointIds_, forcePointIds_;
  BodyStates states(const std::vector<BodyIndex>& bodies, const std::vector<std::vector<int>>& used,
                    const std::vector<std::vector<int>>& usedQ, const double* q) const;
};

}  // namespace flexmbd
