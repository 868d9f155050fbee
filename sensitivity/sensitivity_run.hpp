/// @file
/// A run with forward sensitivities (docs/sensitivities.md): the state y(t) of the DAE
/// F(t, y, y', p) = 0 and its derivatives s_i = dy/dp_i with respect to scene parameters,
/// by IDAS (staggered corrector; HindmarshEtAl2005). dF/dp_i is a five-point central difference
/// (AbramowitzStegun1964, eq. 25.3.6) of the
/// residuals of four systems built from the scene with p_i +- h_i and p_i +- 2 h_i, at the
/// same (t, y, y').
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/sensitivity_problem.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// The magnitude a parameter at 0 (an offset, an initial velocity) takes its step from (SI
/// units of the key: a step of 1e-3), and the scale below which the sensitivities'
/// tolerances are not tightened further (PerturbedDaes::scales).
inline constexpr double kParameterTypicalMagnitude = 1.0;
/// Relative step of the parameters' five-point differences (kStencilWeights). Their total
/// error h^4 |f^(5)| / 30 (AbramowitzStegun1964, eq. 25.3.6) + 0.95 eps |f| / h is smallest
/// at eps^(1/5) = 7.4e-4; the step is
/// a little longer because the round-off is noise to the integrator (it does not shrink
/// with the step: an error test at rtol 1e-10 chased it down to h = 5e-15 with the
/// three-point difference at eps^(1/3)), where the truncation is a smooth bias
/// (3e-14 of f' for f^(5) ~ f' / p^4).
inline constexpr double kParameterStepFraction = 1e-3;
/// Relative noise floor of the sensitivities: p s is known to a small fraction of the
/// state's scale only (dF/dp carries the round-off 0.95 eps |F| / h ~ 2e-13 of the
/// residual's scale; the residual's own terms, the initial sensitivities theirs), and the
/// sensitivities' absolute tolerances are held above this fraction, or the error test
/// chases the noise. Measured: rtol 1e-11, atol 1e-13 failed at the first steps of a
/// pendulum with 1e-12 and the three-point difference; with the five-point one, the nodal
/// elastic crank's crank speed at rtol 1e-10 still failed at 3.5 ms with 1e-12, and runs
/// with 1e-10.
inline constexpr double kSensitivityNoiseFloor = 1e-10;
/// The sensitivities' absolute tolerances (n x count): atol_j max(1, floor L / atol) /
/// |scale_i|, atol_j the state's, L the model size, `atol` the frame positions' tolerance
/// (the class tolerances are atol times the class's scale over L, so the factor holds each
/// class at kSensitivityNoiseFloor of its scale).
MatX sensitivityTolerances(const VecX& atol, double frameAtol, double modelSize, const VecX& scales);
/// The step h = kParameterStepFraction |p| of a parameter of value p (the fraction of
/// `typical` for p = 0), rounded so that p + h and p - h are exact in floating point (p +- 2 h
/// to half an ulp of p: 1e-13 of h, the difference's round-off). Relative to p, it never
/// crosses zero (a mass, an inertia, a section dimension stay valid) and its truncation
/// error is relative to p's own scale (a section of 8 mm gets 8e-6 m, not 1e-3 m). The scenes take typical = 1 (SI units),
/// and |p| for a small non-zero p whose step would cross zero (buildSensitivityScenes).
double parameterStep(double p, double typical = kParameterTypicalMagnitude);

/// One parameter of a sensitivity run: its name (the scene path), value and step h, and
/// the systems built from the scene with p + kStencilOffsets[j] h (finalized, outliving
/// the run).
struct SensitivityParameter {
  std::string name;
  double value = 0.0;
  double step = 0.0;
  std::array<const System*, kStencilPoints> systems{};
};

/// The state moved along a sensitivity: (q + o_j h s_q, v + o_j h s_v) on the system at
/// p + o_j h (o_j = kStencilOffsets[j]), with their accelerations and multipliers. An
/// output c evaluated on them gives dc/dp = sum_j w_j c(at[j]) / h (stencilDerivative),
/// its total derivative: through the state and through the parameter.
struct PerturbedSamples {
  std::array<OutputSample, kStencilPoints> at;
};

/// Sensitivities at one output: dq/dp (nq x count), dv/dp (nv x count), and the
/// perturbed samples per parameter.
struct SensitivitySample {
  MatX q, v;
  std::vector<PerturbedSamples> perturbed;
};

using SensitivityCallback = std::function<void(const OutputSample&, const SensitivitySample&)>;

/// Options of the sensitivities (SensitivityProblem::errorControl).
struct SensitivitySettings {
  bool errorControl = true;
};

/// dF/dp_i of the systems at p + o_j h, at the same (t, y, y'), each system with its
/// scratch (evaluations allocate nothing), from the terms that can differ only
/// (DaeSystem::residualOfParts):
/// - the terms of time: every driver and every force that depends on time;
/// - the terms of the state only (bodies, joints, forces of the state): those that differ
///   between the systems at p + h and p - h at two test states (a term of the state that
///   agrees to the last bit at a generic state is the same term).
/// A section dimension of one beam body thus costs that body's terms (and the drivers'),
/// not the whole model's; an initial condition the drivers' only.
/// The terms of time take the five-point difference sum_j w_j F_j / h (kStencilWeights;
/// AbramowitzStegun1964, eq. 25.3.6):
/// error h^4 |F^(5)| / 30 plus 0.95 eps |F| / h. The terms of the state take it too, unless
/// they are linear in p at the test states (a mass, a density, a Young's modulus, a
/// stiffness): then the two-point difference (F(p + 2h) - F(p - 2h)) / (4 h), exact for
/// them, at half the cost (linear: its difference from the two-point difference at p +- h,
/// h^2 |F'''| / 2, within 8 eps sum_j |F_j| / h on every row, which the round-off
/// 0.5 eps sum_j |F_j| / h of a linear term stays under).
class ResidualDifferences final : public ParameterDerivatives {
 public:
  /// The systems of one parameter at p + kStencilOffsets[j] step (the DAEs outlive this object).
  struct Stencil {
    std::array<const DaeSystem*, kStencilPoints> daes{};
    double step = 0.0;
  };
  /// The test states are (y0, y0') and a generic state near it (every entry moved).
  ResidualDifferences(std::vector<Stencil> stencils, double t0, const VecX& y0, const VecX& yp0);
  int count() const override { return static_cast<int>(stencils_.size()); }
  void residualDerivative(int i, double t, const double* y, const double* yp, double* dFdp) override;
  /// The terms evaluated for parameter i.
  const ResidualParts& parts(int i) const { return parts_[static_cast<std::size_t>(i)].all; }
  /// Whether parameter i's terms of the state take the two-point difference (linear in p).
  bool linearTerms(int i) const { return parts_[static_cast<std::size_t>(i)].anyPair; }

  /// A parameter's terms: all of them, those of the five-point difference and those of
  /// the two-point one.
  struct Split {
    ResidualParts all, stencil, pair;
    bool anyStencil = false, anyPair = false;
  };

 private:
  std::vector<Stencil> stencils_;
  std::vector<Split> parts_;
  std::vector<std::array<std::unique_ptr<DaeScratch>, kStencilPoints>> scratch_;  ///< per parameter and point
  VecX term_;  ///< one point's residual terms
};

/// Consistent initial sensitivities: s0 = dy0/dp, s0' = dy0'/dp by five-point differences
/// (AbramowitzStegun1964, eq. 25.3.6)
/// of the engine's consistent initialisation (computeConsistentState, with the same released
/// equations) on the perturbed systems, so the constraint projection is differentiated too.
struct InitialSensitivities {
  MatX s0, sp0;  ///< n x count
};
/// @pre `base` the DAE of the run, `stencils` those of the perturbed systems (same
/// layout), `init` the base consistent state.
InitialSensitivities initialSensitivities(const DaeSystem& base, const std::vector<ResidualDifferences::Stencil>& stencils,
                                          const ConsistentState& init, double t0);

/// The differences' s0 satisfies the differentiated constraints only to the consistent
/// initialisation's Newton tolerance divided by h (~6e-13 of the position scale), more
/// than the sensitivities' absolute tolerances at tight rtol: the first step's corrector
/// would move s_q by that much at any step size and the error test fail down to h ~ 1e-15.
/// This makes the minimum-norm corrections of s_q and then s_v (GGL) that zero the
/// constraint rows of F_y s + F_p at t0 (index 3: s_q only; index 1: nothing).
void projectOntoConstraints(const DaeSystem& base, const std::vector<ResidualDifferences::Stencil>& stencils,
                            const ConsistentState& init, double t0, MatX& s0);

/// Refuses a parameter whose perturbed system changes the structure of the DAE: another
/// number of coordinates, velocities or constraint equations, or another Jacobian pattern.
/// @throws InputError naming the parameter and what changed.
void requireSameStructure(const DaeSystem& base, const DaeSystem& perturbed, const std::string& parameter);

/// The settings of a run with sensitivities (forward or adjoint): `given` with the
/// integrator IDA. @throws InputError naming the key: an integrator other than ida or
/// auto, an elastic start other than "given", fd_jacobian (`what`: "forward sensitivities").
SolverSettings sensitivityRunSettings(const SolverSettings& given, const std::string& what);

/// The DAEs of the perturbed systems of every parameter (same formulation and released
/// equations as `base`), checked for the base's structure, their stencils and the
/// parameters' scales max(|p|, kParameterTypicalMagnitude).
struct PerturbedDaes {
  std::vector<std::unique_ptr<DaeSystem>> daes;
  std::vector<ResidualDifferences::Stencil> stencils;
  VecX scales;
};
/// @throws InputError naming a parameter without a finalized system or one that changes the structure.
PerturbedDaes perturbedDaes(const DaeSystem& base, const std::vector<SensitivityParameter>& parameters);

/// Stage "start" of a run with sensitivities (forward or adjoint): the consistent state of
/// the system's initial values (released equations as the settings say), its DAE and the
/// parameters' perturbed DAEs.
struct SensitivityStart {
  ConsistentState init;
  std::unique_ptr<DaeSystem> dae;
  PerturbedDaes perturbed;
};
/// @throws as computeConsistentState and perturbedDaes.
SensitivityStart startSensitivityRun(const System& sys, const SolverSettings& settings,
                                     const std::vector<SensitivityParameter>& parameters);

/// simulateKeepingFailures with forward sensitivities, on IDA(S) only (no hand-over to
/// Radau IIA, no singular crossing: a run that fails stops there, rows kept). `onOutput`
/// gets every output with its sensitivities.
/// @throws InputError: an integrator other than ida or auto in the settings, an elastic
/// start other than "given", a parameter that changes the structure; ModelError as simulate.
SimulationSummary simulateWithSensitivities(const System& sys, const std::vector<SensitivityParameter>& parameters,
                                            const SolverSettings& settings, const SensitivitySettings& sensitivity,
                                            const SensitivityCallback& onOutput);

}  // namespace flexmbd
