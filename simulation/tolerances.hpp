/// @file
/// Tolerances by coordinate class: the defaults relative to the model's own
/// sizes, the override of rtol/atol that scales every class together (command line,
/// Python, C++), and the absolute tolerance of every unknown a run hands to its integrator.
/// docs/scene-format.md (Solver) and docs/formulations.md ("Tolerances by coordinate
/// class") state the rules key by key.
#pragma once

#include <optional>
#include <string>

#include "core/dae_system.hpp"

namespace flexmbd {

struct SolverSettings;

/// The model's own sizes the default class tolerances are relative to.
struct ModelScales {
  double length = 1.0;     ///< L (m): System::characteristicLength()
  /// V0 (m/s): largest speed at the start: frame speeds, angular rates times L, the speed
  /// sqrt(|g| L) of a fall through L; at least L / (t_end - t_start).
  double speed = 1.0;
  double timeScale = 1.0;  ///< T = L / V0 (s), at most t_end - t_start (reported: the default velocity tolerance uses 1 s, tolerances.cpp)
  /// s_e (m): the largest over the flexible bodies of the mass-weighted RMS deflection
  /// of their lowest elastic mode under the acceleration L / T^2, quasi-statically:
  /// (L / T^2) / omega_1^2. 0 for a model without elastic coordinates (or without
  /// elastic matrices: spatial flexible bodies). The scale of the elastic round-off floor
  /// and a guide for atol_elastic (about rtol times the coordinates' expected size); not
  /// the default's scale: atol s_e / L falls like 1 / E on a stiffening rod, and the
  /// modal crank's steps grew from 1,988 to 21,223 from E x 1 to E x 1e4
  /// (tests/test_stability.cpp, StiffRod), where atol keeps them flat; on Simeon's crank
  /// s_e = 6.2e-3 m overestimates the deflections (2e-4 m and less) 30 to 1000 times.
  double elasticSize = 0.0;
  std::string elasticBody;  ///< the body of s_e ("" if none)
  double lowestFrequency = 0.0;  ///< its omega_1 (rad/s), 0 if none
};

/// The scales of `sys` with initial velocities `v0` (consistent ones: a driver's speed
/// counts) over [tStart, tEnd]. @pre sys finalized, v0.size() == sys.numVelocities(),
/// tEnd > tStart.
ModelScales modelScales(const System& sys, const VecX& v0, double tStart, double tEnd);

/// The same from the consistent initial state of `sys` at settings.tStart.
/// @throws ModelError as computeConsistentState.
ModelScales modelScales(const System& sys, const SolverSettings& settings);

/// The tolerances a run uses, by coordinate class. The velocities of each class get
/// its position tolerance times atol_velocity / atol (by default: over the time scale T).
struct ClassTolerances {
  double rtol = 0.0;
  double position = 0.0;         ///< frame positions (m): atol
  double angle = 0.0;            ///< frame angles (rad)
  double elastic = 0.0;          ///< elastic coordinates (unit of q_f, a length for a nodal or modal coordinate)
  double velocity = 0.0;         ///< frame velocities (m/s)
  double angularVelocity = 0.0;  ///< angular velocities (rad/s)
  double elasticVelocity = 0.0;  ///< rates of elastic coordinates
};

/// Round-off floors of the absolute tolerances. Positions: 1e-15 of the model size L
/// (positions of that size carry round-off of 1e-16 of it); a finer atol is refused
/// (simulate). Angles: 1e-15 rad. Elastic coordinates: 1e-15 of their size s_e (L if
/// unknown): they are small and carry round-off of their own size, not of L. Velocities
/// of every class: 1e-16 of the speed scale V0 (rad/s: V0 / L): the velocity constraints
/// G v = f' are met to round-off of G v, about 1e-16 V0, and their Newton corrections
/// carry that noise into the velocities of the bodies they join (elastic rates
/// included); below it the corrector cannot converge (Simeon's crank, GGL, rtol 1e-12:
/// elastic rate tolerance 7e-18 V0 fails at t = 1e-11 with any min_step, 7e-17 V0 runs).
/// Finer class tolerances, which a scene's ratio scaled by --atol can give, are raised
/// to their floors.
inline constexpr double kRoundOffFractionOfSize = 1e-15;
inline constexpr double kRoundOffAngle = 1e-15;
inline constexpr double kRoundOffFractionOfSpeed = 1e-15;

/// Effective tolerances of `s` for a model of scales `m`: the classes `s` sets as given,
/// the others by default relative to atol and the model's sizes:
///   angle    = atol (in rad)        (atol / L, the rotation moving a point at L by atol,
///              was measured and not kept: tolerances.cpp)
///   velocity = atol / (1 s)         (a speed error that moves it by atol within 1 s)
///   elastic  = atol                 (a nodal or modal coordinate moves material points by
///              its own value; see ModelScales::elasticSize for why not atol s_e / L);
/// angular and elastic rates: angle and elastic times velocity / atol. Each raised to
/// its round-off floor.
ClassTolerances classTolerances(const SolverSettings& s, const ModelScales& m);

/// Absolute tolerance of every unknown of the DAE: per coordinate class and their
/// velocities; multipliers out of the error and convergence tests (1e10).
VecX absoluteTolerances(const DaeSystem& dae, const ClassTolerances& tol);

/// Overrides rtol and/or atol as the command line's --rtol/--atol do, keeping the scene's
/// balance between the classes: every absolute tolerance `s` holds (atol and the class
/// tolerances it sets: atol_angle, atol_elastic, atol_velocity) is scaled by
/// newAtol / atol; with rtol alone, by newRtol / rtol (tightening rtol tightens every
/// class, the elastic coordinates included). Class tolerances left to their defaults
/// follow atol by their definition. Nothing given: unchanged.
/// @throws InputError if a given value is not positive and finite.
void overrideTolerances(SolverSettings& s, std::optional<double> rtol, std::optional<double> atol);

}  // namespace flexmbd
