/// @file
/// The interface of force elements (springs, dampers, applied loads).
#pragma once

#include <string>
#include <vector>

#include "core/constraint.hpp"

namespace flexmbd {

/// A force element adds generalised forces Q(t, q, v) over the local velocities of its
/// bodies, v_local = [used velocities of body 0; of body 1; ...] (see BodyState): Q and
/// v are nv_local, dQ/dq is nv_local x nq_local, dQ/dv nv_local x nv_local.
/// Added to a System with System::addForce (or the builders' addSpringDamper(sys, ...),
/// ...); the system sums the Q of all force elements into the equations of motion.
class Force {
 public:
  /// @param name unique in the system (among bodies, constraints and forces).
  /// @param bodies the bodies the force acts on, in the order of BodyStates.
  Force(std::string name, std::vector<BodyIndex> bodies)
      : name_(std::move(name)), bodies_(std::move(bodies)) {}
  virtual ~Force() = default;
  Force(const Force&) = delete;
  Force& operator=(const Force&) = delete;

  const std::string& name() const { return name_; }  ///< The name given at construction.
  const std::vector<BodyIndex>& bodies() const { return bodies_; }  ///< The bodies it acts on.
  /// "spring_damper", "applied_load", "rotational_spring_damper", "bushing", ...
  virtual std::string typeName() const = 0;
  /// Body points the force attaches to, resolved by System::finalize() into the
  /// identifiers BodyStates::pointId(k) gives in this order.
  virtual std::vector<Attachment> attachments() const { return {}; }

  /// Q += generalised force; if dQdq / dQdv are given, they receive += its derivatives.
  /// `work` is the caller's working memory for this force: with it kept between calls,
  /// evaluations allocate nothing.
  virtual void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv,
                        KinematicsWork& work) const = 0;
  /// The same with working memory made for the call (allocates; outputs and tests).
  void addForce(double t, const BodyStates& bodies, const VecX& v, VecX& Q, MatX* dQdq, MatX* dQdv) const {
    KinematicsWork work;
    addForce(t, bodies, v, Q, dQdq, dQdv, work);
  }
  /// Potential energy, for forces deriving from one (springs).
  virtual double potentialEnergy(const BodyStates& bodies) const {
    (void)bodies;
    return 0.0;
  }
  /// True if the force is the negative gradient of potentialEnergy (no damping, no
  /// prescribed loads): then the total energy of an undriven model is conserved.
  virtual bool isConservative() const = 0;
  /// True if Q depends on time explicitly (a prescribed load, a user law of t); false for
  /// a force of the state only, which a sensitivity run leaves out of dF/dp where its terms
  /// do not change with the parameter (ResidualDifferences).
  virtual bool dependsOnTime() const { return true; }

 private:
  std::string name_;
  std::vector<BodyIndex> bodies_;
};

}  // namespace flexmbd
