/// @file
/// A run with forward sensitivities (docs/sensitivities.md): the state y(t) of the DAE
/// F(t, y, y', p) = 0 and its derivatives s_i = dy/dp_i with respect to scene parameters,
/// by IDAS (staggered corrector). dF/dp_i is a central difference of the residuals of two
/// systems built from the scene with p_i + h_i and p_i - h_i, at the same (t, y, y').
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/sensitivity_problem.hpp"
#include "integrators/simulation.hpp"

namespace flexmbd {

/// Magnitude below which a parameter's step is taken from 1 (SI units of the key): a
/// parameter at 0 (an offset, an initial velocity) still gets a step of 6e-6.
inline constexpr double kParameterTypicalMagnitude = 1.0;
/// Relative noise floor of the sensitivities: dF/dp by central differences carries the
/// round-off eps |F| / (2 h) = eps^(2/3) / 2 ~ 2e-11 of the residual's scale, so p s is
/// known to about that fraction of the state's scale; the sensitivities' absolute
/// tolerances are held above 5 times it (otherwise the error test chases the noise: rtol
/// 1e-11, atol 1e-13 failed at the first steps of a pendulum).
inline constexpr double kSensitivityNoiseFloor = 1e-10;
/// The sensitivities' absolute tolerances (n x count): atol_j max(1, floor L / atol) /
/// |scale_i|, atol_j the state's, L the model size, `atol` the frame positions' tolerance
/// (the class tolerances are atol times the class's scale over L, so the factor holds each
/// class at kSensitivityNoiseFloor of its scale).
MatX sensitivityTolerances(const VecX& atol, double frameAtol, double modelSize, const VecX& scales);
/// The step h = eps^(1/3) max(|p|, typical) of a parameter of value p, rounded so that
/// p + h and p - h are exact in floating point. The scenes take typical = 1 (SI units),
/// and |p| for a small non-zero p whose step would cross zero (buildSensitivityScenes).
double parameterStep(double p, double typical = kParameterTypicalMagnitude);

/// One parameter of a sensitivity run: its name (the scene path), value and step, and the
/// system built from the scene with p + h and with p - h (finalized, outliving the run).
struct SensitivityParameter {
  std::string name;
  double value = 0.0;
  double step = 0.0;
  const System* plus = nullptr;
  const System* minus = nullptr;
};

/// The state moved along a sensitivity: (q + e h s_q, v + e h s_v) with e = +1 on the
/// system at p + h and e = -1 on the one at p - h, with their accelerations and
/// multipliers. An output c evaluated on them gives dc/dp = (c(plus) - c(minus)) / (2h),
/// its total derivative: through the state and through the parameter.
struct PerturbedSamples {
  OutputSample plus, minus;
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

/// dF/dp_i = (F_{p+h}(t, y, y') - F_{p-h}(t, y, y')) / (2 h): error h^2 |F_ppp| / 6 plus
/// eps |F| / h; each system with its scratch, so evaluations allocate nothing. Only the
/// terms that can differ are evaluated (DaeSystem::residualOfParts): every force and
/// constraint, and the bodies whose terms differ between the two systems at two test
/// states (body terms depend on the state only, not on time: a body whose terms agree to
/// the last bit at a generic state is the same body). A section dimension of one beam
/// body thus costs that body's terms, not the whole model's; an initial condition none.
class ResidualDifferences final : public ParameterDerivatives {
 public:
  /// One pair of systems per parameter (the DAEs outlive this object).
  struct Pair {
    const DaeSystem* plus = nullptr;
    const DaeSystem* minus = nullptr;
    double step = 0.0;
  };
  /// The test states are (y0, y0') and a generic state near it (every entry moved).
  ResidualDifferences(std::vector<Pair> pairs, double t0, const VecX& y0, const VecX& yp0);
  int count() const override { return static_cast<int>(pairs_.size()); }
  void residualDerivative(int i, double t, const double* y, const double* yp, double* dFdp) override;
  /// The terms evaluated for parameter i.
  const ResidualParts& parts(int i) const { return parts_[static_cast<std::size_t>(i)]; }

 private:
  std::vector<Pair> pairs_;
  std::vector<ResidualParts> parts_;
  std::vector<std::unique_ptr<DaeScratch>> plusScratch_, minusScratch_;
  VecX minusResidual_;
};

/// Consistent initial sensitivities: s0 = dy0/dp, s0' = dy0'/dp by central differences of
/// the engine's consistent initialisation (computeConsistentState, with the same released
/// equations) on the perturbed systems, so the constraint projection is differentiated too.
struct InitialSensitivities {
  MatX s0, sp0;  ///< n x count
};
/// @pre `base` the DAE of the run, `plus`/`minus` those of the perturbed systems (same
/// layout), `init` the base consistent state.
InitialSensitivities initialSensitivities(const DaeSystem& base, const std::vector<ResidualDifferences::Pair>& pairs,
                                          const ConsistentState& init, double t0);

/// The differences' s0 satisfies the differentiated constraints only to the consistent
/// initialisation's Newton tolerance divided by 2h (~5e-11 of the position scale), more
/// than the sensitivities' absolute tolerances at tight rtol: the first step's corrector
/// would move s_q by that much at any step size and the error test fail down to h ~ 1e-15.
/// This makes the minimum-norm corrections of s_q and then s_v (GGL) that zero the
/// constraint rows of F_y s + F_p at t0 (index 3: s_q only; index 1: nothing).
void projectOntoConstraints(const DaeSystem& base, const std::vector<ResidualDifferences::Pair>& pairs,
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
/// equations as `base`), checked for the base's structure, their pairs and the
/// parameters' scales max(|p|, kParameterTypicalMagnitude).
struct PerturbedDaes {
  std::vector<std::unique_ptr<DaeSystem>> daes;
  std::vector<ResidualDifferences::Pair> pairs;
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
