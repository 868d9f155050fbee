/// @file
/// "integrator": "auto" (docs/formulations.md, "Why a nodal rod takes so
/// many steps, and what auto does about it"): the integrator and the error weights a run
/// uses, chosen from the model at the start, with the reason in one line for summary.json
/// and the progress output; and the quasi-static elastic start of fast modes.
#pragma once

#include <string>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// Elastic velocities of one body weighed in energy: their absolute tolerance is omega
/// times that of the body's elastic coordinates (a velocity error dv of a mode of
/// frequency omega becomes the displacement error dv / omega). With omega the body's
/// highest frequency this is exact in energy for its fastest mode and looser for slower
/// ones, whose displacements the position test holds (accuracy measured: docs/formulations.md).
struct EnergyVelocityWeight {
  std::string body;
  int velocityOffset = 0;    ///< first elastic velocity of the body in v
  int coordinateOffset = 0;  ///< first elastic coordinate of the body in q
  int size = 0;              ///< number of elastic coordinates
  double omega = 0.0;        ///< rad/s: the body's highest natural frequency
};

struct IntegratorChoice {
  IntegratorKind kind = IntegratorKind::Ida;  ///< never Automatic
  std::string reason;                         ///< one line: what was measured and why this
  /// Bodies whose elastic velocities are weighed in energy (Radau IIA only; empty for a
  /// choice given in the settings).
  std::vector<EnergyVelocityWeight> energyWeights;
  /// IDA on a stiff model without elastic coordinates (given in the settings, or kept by
  /// IDA's own options): a warning for summary.json that its error may be hundreds of
  /// times rtol there ("" otherwise; docs/stability.md, section 7).
  std::string warning;
};

/// Models without elastic coordinates and with more independent coordinates than this are
/// not analysed for stiffness (dense eigenproblem of the reduced linearised model).
inline constexpr int kMaxStiffnessAnalysisSize = 400;
inline constexpr int kMaxStiffnessAnalysisVelocities = 300;  ///< nor with more velocities (dense SVD of G: +0.2 s at 300, a planar chain of 100 links; +1 s at 600)

/// A model without elastic coordinates goes to Radau IIA (radau5) when its fastest
/// linearised eigenvalue |s| exceeds this times the output Nyquist frequency: a motion
/// that fast is below what any output shows, the mark of a stiff force element (the A05
/// governor: 8,120 /s against 314 rad/s; its soft variant, k and c / 100: 45 /s, stays
/// with IDA).
inline constexpr double kStiffRateOverNyquist = 1.0;

/// The fastest eigenvalue of the model linearised at its consistent start (linearize,
/// reduce, computeModes over all modes); analysed = false if the model could not be
/// linearised or is larger than kMaxStiffnessAnalysisSize independent coordinates.
struct FastestRate {
  bool analysed = false;
  double omega = 0.0;         ///< |s| (rad/s or 1/s)
  double dampingRatio = 0.0;  ///< -Re(s) / |s|
};
FastestRate fastestLinearRate(const System& sys, const SolverSettings& settings);

/// The warning IntegratorChoice::warning carries when IDA runs a model without elastic
/// coordinates whose fastest linearised eigenvalue is above the output Nyquist frequency;
/// "" otherwise.
std::string stiffModelIdaWarning(const System& sys, const SolverSettings& settings);

/// The highest natural frequency an output step resolves: the Nyquist frequency pi / dt.
double outputNyquistFrequency(const SolverSettings& settings);

/// The integrator for the run. An explicit settings.integrator is kept (reason "given in
/// the settings"). Automatic: IDA (variable-order BDF) unless a flexible body has
/// elastic modes above the Nyquist frequency of the output step (modes no output can
/// show); then Radau IIA, whose L-stability damps the modes it does
/// not resolve where BDF3-5 are unstable near the imaginary axis and must resolve them,
/// with that body's elastic velocities weighed in energy at its highest frequency (the
/// velocity test asks no more of a mode than the position test does of the fastest one).
/// A model without elastic coordinates: IDA, unless its fastest linearised eigenvalue at
/// the start is above the output Nyquist frequency (fastestLinearRate: a stiff spring or
/// damper); then radau5 (docs/stability.md, "Stiff force elements").
/// @pre sys is finalized, settings validated.
IntegratorChoice chooseIntegrator(const System& sys, const SolverSettings& settings);

/// atol of the elastic velocities of each body in choice.energyWeights raised to omega
/// times the atol of its elastic coordinates (never lowered).
/// @pre atol has the DAE size of `layout`.
void applyEnergyVelocityWeights(const IntegratorChoice& choice, const DaeLayout& layout, VecX& atol);

/// settings.elasticStart QuasiStatic: `init` with the elastic modes above
/// settings.quasiStaticAbove (default: the output Nyquist frequency) moved to their
/// quasi-static deflection and rate (analysis/quasi_static_start.hpp); `report` gets one
/// line for summary.json. Given: `init` unchanged, `report` empty.
/// @throws ModelError if the quasi-static state cannot be found.
ConsistentState elasticStartState(const System& sys, const SolverSettings& settings, const ConsistentState& init,
                                  std::string& report);

}  // namespace flexmbd
