/// @file
/// Method 1 of Doc001 (Tamba & Kanno): inextensible cables, struts with
/// finite stiffness, nonsmooth time-stepping with one LCP per step (docs/tensegrity.md).
///
/// Over [t_i, t_f], dt = t_f - t_i, with the midpoint u_m = u_i + v_i dt/2:
///   M (v_f - v_i) = (f(t_m) - g(u_m)) dt - sum_{c in A} b_c(u_m) p_c
///   w_c = -b_c(u_m)^T v_f >= 0,  p_c >= 0,  p_c w_c = 0          (c in A)
///   u_f = u_m + v_f dt/2
/// where g is the elastic force of the struts (and of elastic cables), p_c the tension
/// impulse of cable c and A the cables at (or beyond) their natural length at u_m. The
/// LCP is  w = W p + q,  W = B M^-1 B^T,  q = -B v_free,  v_free = v_i + M^-1 (f - g) dt,
/// the KKT system of the document's QP  min 1/2 v^T M v + (-M v_i + ...)^T v  s.t. B v <= 0.
/// The mass matrix is constant here (point masses and bar masses do not depend on u),
/// so M^m = M. Position drift of taut cables (l > l0 at u_f) is removed by a projection,
///   u <- u - M^-1 B^T lambda,  lambda >= 0,  l0 - l + W lambda >= 0, complementary,
/// iterated (Gauss-Newton) until the relative drift is below the projection tolerance.
#pragma once

#include <optional>
#include <string>

#include "tensegrity/lcp_solver.hpp"
#include "tensegrity/tensegrity_output.hpp"
#include "tensegrity/tensegrity_structure.hpp"

namespace flexmbd {

struct TimeSteppingSettings {
  double tStart = 0.0;
  double tEnd = 1.0;
  double timeStep = 1e-3;
  /// Output every round(outputStep / timeStep) steps (0: every step); the last step
  /// is shortened to end at tEnd and is always output.
  double outputStep = 0.0;
  LcpOptions lcp;
  bool projectPositions = true;
  double projectionTolerance = 1e-12;  ///< on (l - l0)/l0 of inextensible cables
  int maxProjectionIterations = 20;
  /// A cable is slack when l < l0 (1 - slackTolerance); cables with l(u_m) >= l0 (1 -
  /// slackTolerance) enter the LCP.
  double slackTolerance = 1e-9;
  /// A snap needs a pre-step elongation rate above this (length/time).
  double snapRateTolerance = 1e-8;
  bool detectContacts = false;
  /// Contact as a unilateral constraint (scene key solver.contact_constraints): every pair
  /// of members sharing no node whose gap d - (r_a + r_b) at u_m is <= slackTolerance * L
  /// (L: mean initial length of the two members) enters the same LCP as the cables, in
  /// rate form: w = (d gap/du) v_f >= 0, impulse p >= 0 along the normal of the closest
  /// points (inelastic: the normal relative velocity is zero after the contact step);
  /// penetration -gap/L is removed by the same projection as the cable drift.
  bool contactConstraints = false;
};

class TensegrityTimeStepper {
 public:
  /// @pre structure finalized and outliving the stepper.
  /// @throws InputError on invalid settings (dt <= 0, tEnd <= tStart, ...).
  TensegrityTimeStepper(const TensegrityStructure& structure, const TimeSteppingSettings& settings);

  /// Runs from the structure's initial state. Never throws on solver failure: the
  /// summary says ok = false with the step, the time and the LCP residual; samples and
  /// events up to the failure have been delivered.
  TensegrityRunSummary run(const TensegrityObserver& observer) const;

 private:
  const TensegrityStructure& s_;
  TimeSteppingSettings settings_;
};

/// The energy check of a step with a snap (an inelastic impulse, which dissipates): the
/// message ending the run if the energy went from energyBefore to energyAfter by more
/// than loadWork (the loads' work over the step, the only input the potential energy does
/// not contain) plus 1e-6 of the energy (round-off of the LCP and the projection: 1e-12);
/// energy from nothing means the model's numbers overflow (R03: 1e-323 J to 2 J).
std::optional<std::string> snapEnergyGrowth(double energyBefore, double energyAfter, double loadWork);

}  // namespace flexmbd
