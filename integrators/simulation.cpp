#include "integrators/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <limits>
#include <sstream>

#include <Eigen/SVD>

#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/augmented_lagrangian_integrator.hpp"
#include "integrators/bdf_stability.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/integrator_choice.hpp"

namespace flexmbd {
namespace {

void requireSetting(bool ok, const std::string& key, const std::string& expected, double got) {
  if (!ok) {
    std::ostringstream os;
    os << "solver." << key << ": expected " << expected << ", got " << got;
    throw InputError(os.str());
  }
}

/// Progress on stderr for runs longer than a few seconds, when stderr is a terminal.
class ProgressReporter {
 public:
  ProgressReporter(bool enabled, double t0, double tEnd, std::string integrator)
      : enabled_(enabled && isatty(STDERR_FILENO)), t0_(t0), tEnd_(tEnd), integrator_(std::move(integrator)),
        start_(std::chrono::steady_clock::now()), last_(start_) {}
  void update(double t, long steps) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < 2.0 || std::chrono::duration<double>(now - last_).count() < 0.5) return;
    last_ = now;
    shown_ = true;
    std::fprintf(stderr, "\r  %s: t = %.6g / %.6g (%5.1f%%), %ld steps, %.0f steps/s   ", integrator_.c_str(), t, tEnd_,
                 100.0 * (t - t0_) / (tEnd_ - t0_), steps, steps / elapsed);
    std::fflush(stderr);
  }
  ~ProgressReporter() {
    if (shown_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  double t0_, tEnd_;
  std::string integrator_;  // the integrator chosen, named in the progress line
  std::chrono::steady_clock::time_point start_, last_;
  bool shown_ = false;
};

/// A constraint row whose Gram-Schmidt remainder falls below this fraction of its norm
/// counts as dependent in a failure diagnosis. Measured (tests/test_stability.cpp): where
/// IDA stops at the lock-up of examples/slider_crank_lockup.json the smallest/largest
/// singular value of G is 1.6e-5, at the crossing of examples/slider_crank_equal_links.json
/// 1e-7; a regular position of the rigid slider-crank has 0.17.
constexpr double kNearlyDependent = 1e-2;

/// After a solver failure at tFail: is the mechanism at a singular position? The last
/// output state is carried to tFail (Taylor, then minimum-norm Newton on g(q, tFail) = 0,
/// which may stop short beyond a lock-up) and the constraint Jacobian G is examined there.
/// A time in a message: 10 significant digits.
std::string fmtTime(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", t);
  return buf;
}

/// Smallest/largest singular value of G at q, or 1 without constraints.
double constraintConditioning(const MatX& G) {
  if (G.rows() == 0) return 1.0;
  const VecX sv = Eigen::JacobiSVD<MatX>(G).singularValues();
  return sv.size() > 0 && sv[0] > 0 ? sv[sv.size() - 1] / sv[0] : 0.0;
}

/// A failure is called "approaching a singular position" when the singular value ratio of
/// G has fallen below this fraction of its value at the start of the run (the model's own
/// regular value): 0.1. Measured: the undriven parallelogram fails at 2e-3 and 2e-4 of
/// its starting 0.35 (rtol 1e-10, 1e-8), 0.015 rad before its change point; the
/// slider-crank made to fail at a regular position stays at 0.3-1x its start.
constexpr double kApproachingSingular = 0.1;

/// Where the DAE integrator stops with the constraint Jacobian G worse conditioned than
/// kCrossingTrigger times at the start, the failure is taken for the approach of a singular
/// position and crossed. Measured on the undriven parallelogram: IDA stops at a singular
/// value ratio of 2e-3 (rtol 1e-8) to 0.33 (rtol 1e-12) of its value at the start.
constexpr double kCrossingTrigger = 0.5;
/// A crossing ends past the failure, where the ratio has grown back to kCrossingEndFactor
/// times its value where it began (at most kCrossingEndConditioning of the start's): IDA
/// fails where the ratio is so small for its tolerance, so it restarts well above that.
constexpr double kCrossingEndFactor = 4.0, kCrossingEndConditioning = 0.9;
/// The core of a crossing, from where it begins until the singular value ratio of G, past
/// its minimum, is back at its value there: ALI3-P takes steps of 1/kCoreStepDivisor of the
/// DAE integrator's last regular step (at its last output) without error test (see
/// AugmentedLagrangianIntegrator::setErrorTest): its error estimate measures the positions
/// along the nearly dependent directions, known only to the Newton tolerance, not the
/// truncation error, and collapses the steps (measured on a multi-parallelogram).
constexpr double kCoreStepDivisor = 2.0;
/// Tolerances of a crossing relative to the run's: ALI3-P is of order 2 against IDA's 5, so
/// its local errors are held smaller for global errors of the same size.
constexpr double kCrossingToleranceFactor = 1e-2;
/// ... but not below rtol 1e-12: at 1e-14 the error estimate h^2/12 (a_{n+1} - a_n) is
/// round-off near the singular position (accelerations along the nearly dependent
/// direction are determined to 1/sigma_min) and the steps collapse (measured).
constexpr double kMinCrossingRtol = 1e-12;
/// ... and absolute ones not below 1e3 round-offs of the model size.
constexpr double kMinCrossingAtolRoundOffs = 1e3;
/// IDA is caught in the order-1 trap when at least kTrapFraction of its steps over a window
/// of kTrapWindow steps failed the error test (measured: 458,257 failures in 460,780 steps
/// on the 4-element crank with Rayleigh beta 3e-4 s, 24 s; Radau IIA: 844 steps, 15
/// failures, 0.03 s). Healthy runs stay below 0.1 (the undamped rod: 1.4 %).
constexpr long kTrapWindow = 2000;
constexpr double kTrapFraction = 0.8;
/// An integrator that fails within this many steps of its restart after a crossing has not
/// left the singular position's neighbourhood: the crossing goes on, to twice the ratio.
constexpr long kRestartSteps = 50;

/// What singularityDiagnosis measured: the message, and whether it found the mechanism at
/// or approaching a singular position (the cases the augmented-Lagrangian bridge crosses).
struct SingularityDiagnosis {
  std::string text;
  bool singular = false;
  double ratio = 1.0;  ///< smallest/largest singular value of G at the failure
};

SingularityDiagnosis singularityDiagnosis(const System& sys, const OutputSample& last, double tFail,
                                          double startRatio) {
  const int m = sys.numConstraintEquations();
  if (m == 0 || last.q.size() == 0 || m > sys.numVelocities()) return {};
  const double dt = tFail - last.t;
  VecX q = sys.applyIncrement(last.q, dt * last.v + 0.5 * dt * dt * last.a);
  VecX g;
  MatX G;
  evaluateConstraints(sys, q, tFail, &g, &G);
  for (int it = 0; it < 10 && g.allFinite() && g.lpNorm<Eigen::Infinity>() > 1e-13 * (1.0 + q.norm()); ++it) {
    const VecX dq = -G.completeOrthogonalDecomposition().solve(g);
    if (!dq.allFinite() || dq.norm() > 0.1 * (1.0 + q.norm())) break;  // diverging: keep the last q
    VecX gn;
    MatX Gn;
    const VecX qn = sys.applyIncrement(q, dq);
    evaluateConstraints(sys, qn, tFail, &gn, &Gn);
    if (!gn.allFinite() || gn.norm() >= g.norm()) break;
    q = qn;
    g = gn;
    G = Gn;
  }
  if (!G.allFinite()) return {};
  const VecX sv = Eigen::JacobiSVD<MatX>(G).singularValues();
  const double ratio = sv.size() > 0 && sv[0] > 0 ? sv[sv.size() - 1] / sv[0] : 0.0;
  const std::vector<int> rows = dependentRows(G, kNearlyDependent);
  bool driven = false;
  for (int c = 0; c < sys.numConstraints(); ++c) driven = driven || sys.constraint(ConstraintIndex(c)).isDriver();
  std::ostringstream os;
  os.precision(3);
  os << "; constraint Jacobian at t = " << fmtTime(tFail) << ": smallest/largest singular value " << ratio << " ("
     << startRatio << " at the start)";
  if (rows.empty()) {
    if (ratio < kApproachingSingular * startRatio) {
      os << ", full rank but " << startRatio / ratio
         << " times worse conditioned than at the start: the mechanism is approaching a singular position";
      return {os.str(), true, ratio};
    }
    os << ", full rank and conditioned as at the start: not a singular position";
    return {os.str(), false, ratio};
  }
  os << ", nearly rank-deficient: ";
  for (size_t k = 0; k < rows.size(); ++k) os << (k ? "; " : "") << sys.describeEquation(rows[k]);
  os << (rows.size() == 1 ? " becomes" : " become") << " dependent on the "
     << (driven ? "joints and drivers" : "joints") << " defined before: "
     << (driven ? "a singular position (lock-up, dead centre or change point) where the drivers do not determine "
                  "the motion"
                : "a singular position of the undriven mechanism (change point or dead centre), where the "
                  "constraints lose rank");
  return {os.str(), true, ratio};
}

/// A crossing of a singular position that failed: the integrator's reason, the diagnosis
/// and why the augmented-Lagrangian bridge could not cross either.
struct CrossingFailure : SolverError {
  using SolverError::SolverError;
};

/// Counts of `more` added to `total`; the last step size and time are those of `more`.
void addStats(IntegratorStats& total, const IntegratorStats& more) {
  total.steps += more.steps;
  total.residualEvals += more.residualEvals;
  total.jacobianEvals += more.jacobianEvals;
  total.nonlinearIterations += more.nonlinearIterations;
  total.nonlinearConvFailures += more.nonlinearConvFailures;
  total.errorTestFailures += more.errorTestFailures;
  total.linearSetups += more.linearSetups;
  total.lastStepSize = more.lastStepSize;
  total.currentTime = more.currentTime;
}

/// A state whose position coordinates exceed this multiple of the model size has
/// diverged: no mechanism of the scene reaches 100 times its own size.
constexpr double kDivergedSize = 100.0;

/// What was measured of a diverged state, or "".
std::string divergenceReport(double largest, double modelSize, double t) {
  if (!(largest > kDivergedSize * modelSize)) return "";
  std::ostringstream os;
  os.precision(3);
  os << "; the solution diverged: a coordinate reached " << largest << " at t = " << fmtTime(t) << ", "
     << largest / modelSize << " times the model size " << modelSize;
  return os.str();
}


}  // namespace

/// Coarsest tolerances accepted. rtol: IDA's error control at 1 % relative error already
/// gives qualitative results only. atol of positions and elastic coordinates: 1 % of the
/// model size, of angles 0.01 rad: above, the error test passes steps whose errors are as
/// large as the mechanism (atol 1e6 on a 0.45 m slider-crank: 18 steps, a constraint
/// violation of 1.87 m, status ok).
constexpr double kMaxRelativeTolerance = 1e-2;
/// Finest tolerances accepted: rtol 1e-14 (about 50 round-offs, IDA cannot meet less);
/// absolute ones 1e-15 of the model size (positions of the size carry round-off of 1e-16
/// of it): finer ones cannot be met and only make IDA shrink its step until max_steps.
/// Velocity tolerances have no floor: their scale is the model's time scale, not known
/// here (slow modes of stiff chains use atol_velocity 1e-16, tests/test_stability.cpp).
constexpr double kMinRelativeTolerance = 1e-14;
constexpr double kMinToleranceFractionOfSize = 1e-15;
constexpr double kMaxToleranceFractionOfSize = 1e-2;
constexpr double kMaxAngleTolerance = 1e-2;
/// Warning thresholds: position constraint violation above 1e-3 of the model size,
/// velocity violation above 1e-3 of the model's velocity scale (largest speed seen, at
/// least size / span), an initial correction above 1e-3 of the size or 1e-3 rad. Ten
/// times below the coarsest tolerance accepted; regular runs stay 1e5 times below them.
constexpr double kWarnFraction = 1e-3;
constexpr double kWarnAngle = 1e-3;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

/// Refuses tolerances that cannot give a meaningful result for this model.
void checkTolerancesForModel(const SolverSettings& s, double L) {
  const auto check = [&](bool ok, const std::string& key, const std::string& expected, double got) {
    if (!ok) throw InputError("solver." + key + ": expected " + expected + ", got " + num(got));
  };
  check(s.rtol <= kMaxRelativeTolerance, "rtol", "at most 1e-2 (coarser gives no meaningful result)", s.rtol);
  check(s.rtol >= kMinRelativeTolerance, "rtol", "at least 1e-14 (finer is below round-off)", s.rtol);
  const double minAbs = kMinToleranceFractionOfSize * L;
  const std::string fineBound = "at least 1e-15 of the model size " + num(L) + " (finer is below round-off)";
  for (const auto& [key, value] : {std::pair<const char*, std::optional<double>>{"atol", s.atol},
                                   {"atol_elastic", s.atolElastic}, {"atol_angle", s.atolAngle}}) {
    if (value) check(*value >= (std::string(key) == "atol_angle" ? kMinToleranceFractionOfSize : minAbs), key,
                     std::string(key) == "atol_angle" ? "at least 1e-15 rad (finer is below round-off)" : fineBound,
                     *value);
  }
  const double maxLength = kMaxToleranceFractionOfSize * L;
  const std::string lengthBound = "at most 1e-2 of the model size " + num(L) + ": " + num(maxLength) +
                                  " (coarser cannot resolve the motion)";
  check(s.atol <= maxLength, "atol", lengthBound, s.atol);
  if (s.atolElastic) check(*s.atolElastic <= maxLength, "atol_elastic", lengthBound, *s.atolElastic);
  if (s.atolAngle) {
    check(*s.atolAngle <= kMaxAngleTolerance, "atol_angle", "at most 1e-2 rad (coarser cannot resolve the motion)",
          *s.atolAngle);
  } else {
    check(s.atol <= kMaxAngleTolerance, "atol", "at most 1e-2 (it is also the tolerance of angles, in rad)", s.atol);
  }
}

/// The largest correction per body of the consistent initialisation, with the joint or
/// driver most violated on that body by the given values.
std::vector<InitialCorrection> initialCorrections(const System& sys, double t0, const VecX& given,
                                                  const VecX& corrected, double L) {
  std::vector<InitialCorrection> out;
  VecX g;
  if (sys.numConstraintEquations() > 0) evaluateConstraints(sys, given, t0, &g, nullptr);
  const std::vector<std::string> names = sys.coordinateNames();
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds();
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int off = sys.coordinateOffset(BodyIndex(b));
    InitialCorrection c;
    c.body = body.name();
    double worst = 0.0;  // change relative to its warning threshold
    for (int k = off; k < off + body.numCoordinates(); ++k) {
      const double d = std::fabs(corrected[k] - given[k]);
      const bool angle = kinds[k] == CoordinateKind::Angle;
      (angle ? c.angle : c.position) = std::max(angle ? c.angle : c.position, d);
      const double rel = d / (angle ? kWarnAngle : kWarnFraction * L);
      if (rel > worst) {
        worst = rel;
        c.coordinate = names[k];
        c.given = given[k];
        c.corrected = corrected[k];
      }
    }
    if (c.position == 0.0 && c.angle == 0.0) continue;
    for (int ci = 0; ci < sys.numConstraints(); ++ci) {
      const Constraint& con = sys.constraint(ConstraintIndex(ci));
      const auto& bodies = con.bodies();
      if (std::find(bodies.begin(), bodies.end(), BodyIndex(b)) == bodies.end()) continue;
      const int row0 = sys.constraintOffset(ConstraintIndex(ci));
      for (int r = row0; r < row0 + con.numEquations(); ++r) {
        if (std::fabs(g[r]) > c.residual) {
          c.residual = std::fabs(g[r]);
          c.constraint = std::string(con.isDriver() ? "driver '" : "joint '") + con.name() + "'";
        }
      }
    }
    out.push_back(c);
  }
  return out;
}

/// Shortest run: the bound of scene numbers (1e100) inverted; below it, squares of the
/// step underflow.
constexpr double kMinTimeSpan = 1e-100;
/// Shortest run relative to |t|: steps of 1e-3 of such a span are still 1e4 round-offs of t.
constexpr double kMinRelativeSpan = 1e-9;
/// Most outputs of a run: 1e8 rows of even a one-body model are 6 GB of results.csv.
constexpr double kMaxOutputs = 1e8;
/// Default min_step: 1e-12 of the span, at most 1e-12 s. Of the span alone, a long run
/// (t_end = 2^31 s) got min_step = 2e-3 s and failed at its first step. 1e-12 s is below
/// every physical time scale of the models (their fastest elastic modes have periods above
/// 1e-6 s): a step that small has collapsed (lock-up, singularity), it does not resolve.
constexpr double kDefaultMinStepFraction = 1e-12;
constexpr double kDefaultMinStepSeconds = 1e-12;

double defaultMinStepSize(const SolverSettings& s) {
  return std::min(kDefaultMinStepFraction * (s.tEnd - s.tStart), kDefaultMinStepSeconds);
}

ElasticStart parseElasticStart(const std::string& name) {
  if (name == "given") return ElasticStart::Given;
  if (name == "quasi_static") return ElasticStart::QuasiStatic;
  throw InputError("solver.elastic_start: unknown elastic start '" + name + "' (expected one of: given, quasi_static)");
}

std::string toString(ElasticStart s) { return s == ElasticStart::QuasiStatic ? "quasi_static" : "given"; }

void SolverSettings::validate() const {
  requireSetting(rtol > 0.0 && std::isfinite(rtol), "rtol", "a positive number", rtol);
  requireSetting(atol > 0.0 && std::isfinite(atol), "atol", "a positive number", atol);
  for (const auto& [key, value] : {std::pair{"atol_velocity", atolVelocity}, std::pair{"atol_angle", atolAngle},
                                    std::pair{"atol_elastic", atolElastic}}) {
    if (value) requireSetting(*value > 0.0 && std::isfinite(*value), key, "a positive number", *value);
  }
  requireSetting(std::isfinite(tStart), "t_start", "a finite number", tStart);
  requireSetting(std::isfinite(tEnd) && tEnd > tStart, "t_end", "a number greater than t_start", tEnd);
  requireSetting(outputStep > 0.0 && std::isfinite(outputStep), "output_step", "a positive number",
                 outputStep);
  // A span the integrator can resolve: IDA refuses a stop time within round-off of t_start
  // (IDA_ILL_INPUT for t_end = 1e-300) and needs steps well above round-off of t.
  const double span = tEnd - tStart;
  requireSetting(span >= kMinTimeSpan && span >= kMinRelativeSpan * std::max(std::fabs(tStart), std::fabs(tEnd)),
                 "t_end", "t_end - t_start >= 1e-100 and >= 1e-9 max(|t_start|, |t_end|) (a span the integrator "
                 "can resolve)", tEnd);
  requireSetting(span / outputStep <= kMaxOutputs, "output_step",
                 "at most 1e8 outputs over t_end - t_start (results.csv would not fit a disk): a larger step",
                 outputStep);
  requireSetting(maxStepSize >= 0.0 && std::isfinite(maxStepSize), "max_step",
                 "a non-negative number (0: no limit)", maxStepSize);
  if (minStepSize) {
    requireSetting(*minStepSize >= 0.0 && std::isfinite(*minStepSize), "min_step",
                   "a non-negative number", *minStepSize);
    requireSetting(*minStepSize < std::min(span, outputStep), "min_step",
                   "less than t_end - t_start and than output_step", *minStepSize);
  }
  requireSetting(initialStepSize >= 0.0 && std::isfinite(initialStepSize), "initial_step",
                 "a non-negative number (0: IDA's estimate)", initialStepSize);
  requireSetting(maxOrder >= 1 && maxOrder <= 5, "max_order", "an integer from 1 to 5",
                 static_cast<double>(maxOrder));
  requireSetting(maxSteps > 0, "max_steps", "a positive integer", static_cast<double>(maxSteps));
  if (quasiStaticAbove) {
    requireSetting(*quasiStaticAbove > 0.0 && std::isfinite(*quasiStaticAbove), "quasi_static_above",
                   "a positive circular frequency (rad/s)", *quasiStaticAbove);
  }
}

/// Multipliers: large, so that the algebraic variables (already out of the error test)
/// stay out of the Newton convergence test too.
constexpr double kAtolMultiplier = 1e10;

VecX absoluteTolerances(const DaeSystem& dae, const SolverSettings& settings) {
  const DaeLayout& L = dae.layout();
  const System& sys = dae.system();
  const double position = settings.atol;
  const double angle = settings.atolAngle.value_or(position);
  const double elastic = settings.atolElastic.value_or(position);
  const double velocityRatio = settings.atolVelocity.value_or(position) / position;
  const auto ofKind = [&](CoordinateKind kind) {
    return kind == CoordinateKind::Position ? position : kind == CoordinateKind::Angle ? angle : elastic;
  };
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds(), vkinds = sys.velocityKinds();
  VecX atol = VecX::Constant(L.size, kAtolMultiplier);
  for (int k = 0; k < L.nq; ++k) atol[L.q + k] = ofKind(kinds[k]);
  for (int k = 0; k < L.nv; ++k) atol[L.v + k] = ofKind(vkinds[k]) * velocityRatio;
  return atol;
}

SimulationSummary simulate(const System& sys, const SolverSettings& settings,
                           const OutputCallback& onOutput) {
  settings.validate();
  if (!sys.isFinalized()) throw InputError("simulate: the system must be finalized first");
  checkTolerancesForModel(settings, sys.characteristicLength());
  const std::clock_t cpuStart = std::clock();
  const double t0 = settings.tStart, tEnd = settings.tEnd;

  SimulationSummary summary;
  // choose: the integrator and its error weights from the model (integrators/integrator_choice.hpp)
  const IntegratorChoice choice = chooseIntegrator(sys, settings);
  summary.integrator = choice.kind;
  summary.integratorReason = choice.reason;
  const ConsistentState init = elasticStartState(
      sys, settings, computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities()),
      summary.elasticStart);
  const DaeSystem dae(sys, settings.formulation);
  const DaeLayout& L = dae.layout();
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);

  summary.initialPositionIterations = init.positionIterations;
  const double modelSize = sys.characteristicLength();
  summary.modelSize = modelSize;
  summary.initialCorrections = initialCorrections(sys, t0, sys.initialCoordinates(), init.q, modelSize);
  for (const InitialCorrection& c : summary.initialCorrections) {
    if (c.position > kWarnFraction * modelSize || c.angle > kWarnAngle) {
      summary.warnings.push_back("initial position of body '" + c.body + "' corrected: " + c.coordinate + " given " +
                                 num(c.given) + ", now " + num(c.corrected) + " (largest change " +
                                 num(c.position) + " in position, " + num(c.angle) + " rad in angle) to satisfy " +
                                 (c.constraint.empty() ? std::string("the joints of other bodies")
                                                       : c.constraint + " (residual " + num(c.residual) +
                                                             " at the given values)"));
    }
  }
  const bool conservative = isConservative(sys);
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds(), vkinds = sys.velocityKinds();
  double maxSpeed = 0.0;  // velocity scale of the warnings: translational, angular rates times size
  OutputSample last;  // the last output, for the diagnosis of a failure
  double largestCoordinate = 0.0;  // largest |position or elastic coordinate| output so far
  double startRatio = 1.0;         // conditioning of G at the start, for the diagnosis
  if (L.m > 0) {
    MatX G0;
    evaluateConstraints(sys, init.q, t0, nullptr, &G0);
    startRatio = constraintConditioning(G0);
  }
  double tOutput = t0;  // the output being evaluated
  ModalParticipation participation(sys);  // modal content of the flexible bodies at the outputs
  auto emit = [&](double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& v) {
    tOutput = t;
    OutputSample s;
    s.t = t;
    s.q = q;
    s.v = v;
    for (int k = 0; k < L.nq; ++k) {
      if (kinds[k] != CoordinateKind::Angle) largestCoordinate = std::max(largestCoordinate, std::fabs(s.q[k]));
    }
    // Accelerations and multipliers recomputed from the state (q, v): as accurate as the
    // state itself, unlike the interpolated y' (docs/formulations.md).
    computeAccelerations(sys, t, s.q, s.v, s.a, s.lambda);
    for (int k = 0; k < L.nv; ++k) {
      maxSpeed = std::max(maxSpeed, std::fabs(s.v[k]) * (vkinds[k] == CoordinateKind::Angle ? modelSize : 1.0));
    }
    if (L.m > 0) {
      VecX g;
      evaluateConstraints(sys, s.q, t, &g, nullptr);
      summary.maxPositionViolation = std::max(summary.maxPositionViolation, g.lpNorm<Eigen::Infinity>());
      summary.maxVelocityViolation = std::max(
          summary.maxVelocityViolation, velocityConstraintResidual(sys, s.q, s.v, t).lpNorm<Eigen::Infinity>());
    }
    const char* bad = !s.q.allFinite() ? "positions" : !s.v.allFinite() ? "velocities"
                      : !s.a.allFinite() ? "accelerations" : !s.lambda.allFinite() ? "multipliers" : nullptr;
    if (bad) throw NonFiniteResult(std::string("non-finite ") + bad + " at t = " + fmtTime(t));
    if (conservative) {
      const double E = kineticEnergy(sys, s.q, s.v) + potentialEnergy(sys, s.q);
      if (!std::isfinite(E)) throw NonFiniteResult("non-finite energy at t = " + fmtTime(t));
      if (!summary.energyStart) summary.energyStart = E;
      summary.energyEnd = E;
    }
    participation.add(s.q, s.v);
    summary.tReached = t;
    if (onOutput) onOutput(s);
    last = std::move(s);
  };
  try {
    emit(t0, y0.segment(L.q, L.nq), y0.segment(L.v, L.nv));
  } catch (const NonFiniteResult& e) {
    // Nothing was integrated: the scene's own values overflow (masses, speeds, loads).
    throw InputError(std::string("the initial state has ") + e.what() +
                     ": values of the scene overflow (check masses, inertias, speeds, loads)");
  } catch (const RunInterrupted& e) {
    summary.ok = false;
    summary.interruptedBySignal = e.signal;
    summary.failureTime = t0;
    summary.message = e.what();
    return summary;
  } catch (const OutputWriteError& e) {
    summary.ok = false;
    summary.outputFailed = true;
    summary.failureTime = t0;
    summary.message = e.what();
    return summary;
  }

  IntegratorOptions o;
  o.rtol = settings.rtol;
  o.atol = absoluteTolerances(dae, settings);
  applyEnergyVelocityWeights(choice, L, o.atol);
  o.maxSteps = settings.maxSteps;
  o.maxStepSize = settings.maxStepSize;
  o.maxOrder = settings.maxOrder;
  if (choice.kind == IntegratorKind::Ida && settings.formulation != Formulation::Index1) {
    // Damped modes outside the A(alpha) sectors of BDF4/5 set off bursts of error-test
    // failures that strand IDA at order 1 with GGL (docs/formulations.md; index 1 measured unaffected)
    const BdfOrderLimit limit = stableBdfOrder(sys, settings.maxOrder);
    o.maxOrder = limit.order;
    summary.orderLimit = limit.reason();
  }
  summary.maxOrder = o.maxOrder;
  o.initialStepSize = settings.initialStepSize;
  o.minStepSize = settings.minStepSize.value_or(defaultMinStepSize(settings));
  o.linearSolver = settings.linearSolver;
  o.finiteDifferenceJacobian = settings.finiteDifferenceJacobian;
  IntegratorKind kind = choice.kind;  // the one running (IDA may hand over to Radau IIA)
  std::unique_ptr<DaeIntegrator> integrator = makeIntegrator(kind, dae, t0, y0, yp0, o);
  summary.usedKlu = integrator->usesKlu();
  IntegratorStats finished;  // statistics of the integrators a crossing replaced, and of the crossings

  ProgressReporter progress(settings.progress, t0, tEnd, toString(choice.kind));
  // Output times t0 + k dt; the last one is exactly t_end (IDASetStopTime).
  const long nOut = std::max(1L, static_cast<long>(std::ceil((tEnd - t0) / settings.outputStep - 1e-9)));
  const auto outputTime = [&](long k) { return k == nOut ? tEnd : std::min(tEnd, t0 + k * settings.outputStep); };
  long k = 1;  // the next output
  double regularStep = 0.0;  // the DAE integrator's last step size at an output: the size of a crossing's steps
  IntegratorStats windowStart;  // the integrator's statistics where the current window of steps began
  const auto totalSteps = [&] { return finished.steps + (integrator ? integrator->stats().steps : 0); };

  // Across a singular position where the integrator stopped: ALI3-P from the last output
  // (whose constraint Jacobian is still regular) past the failure, until G is conditioned
  // again as at kApproachingSingular of the start; then the integrator restarts from a
  // consistent state there. Returns the time reached. @throws CrossingFailure.
  const auto crossSingularPosition = [&](const SolverError& failure, const std::string& diagnosis,
                                         const OutputSample& start, double endFactor) {
    SingularCrossing crossing;
    crossing.tFailure = failure.time();
    crossing.tStart = start.t;
    AugmentedLagrangianOptions bo;
    const double factor = std::max(kCrossingToleranceFactor, kMinCrossingRtol / settings.rtol);
    bo.rtol = settings.rtol * factor;
    // not below round-off of the model's size (coordinates near 0 have weight atol alone)
    bo.atolPosition = (factor * o.atol.segment(L.q, L.nq))
                          .cwiseMax(kMinCrossingAtolRoundOffs * std::numeric_limits<double>::epsilon() * modelSize);
    bo.maxStepSize = settings.maxStepSize;
    bo.minStepSize = o.minStepSize;
    bo.lengthScale = modelSize;
    bo.initialStepSize = regularStep / kCoreStepDivisor;
    AugmentedLagrangianIntegrator ali(sys, start.t, start.q, start.v, start.a, start.lambda, bo);
    const double ratio0 = ali.constraintConditioning();
    const double endRatio = std::min(endFactor * ratio0, kCrossingEndConditioning * startRatio);
    double minRatio = ratio0;
    ali.setErrorTest(false);
    VecX qi, vi;
    try {
      for (long steps = 0;; ++steps) {
        if (steps >= settings.maxSteps) {
          throw SolverError("more than max_steps = " + std::to_string(settings.maxSteps) + " steps", ali.time(),
                            ali.stats().lastStepSize);
        }
        const double t = ali.step(tEnd);
        for (; k <= nOut && outputTime(k) <= t; ++k) {
          ali.interpolate(outputTime(k), qi, vi);
          emit(outputTime(k), qi, vi);
          progress.update(outputTime(k), totalSteps() + ali.stats().steps);
        }
        if (t >= tEnd) break;
        const double ratio = ali.constraintConditioning();
        minRatio = std::min(minRatio, ratio);
        if (ratio > minRatio && ratio >= ratio0) ali.setErrorTest(true);  // the core is passed
        if (t > failure.time() && ratio >= endRatio) break;
      }
    } catch (const SolverError& e) {
      addStats(finished, ali.stats());
      throw CrossingFailure(std::string(failure.what()) + diagnosis +
                                "; crossing it with the augmented Lagrangian integrator (ali3p) from t = " +
                                fmtTime(start.t) + " failed too: " + e.what(),
                            std::max(failure.time(), e.time()), e.stepSize());
    }
    crossing.tEnd = ali.time();
    crossing.steps = ali.stats().steps;
    summary.singularCrossings.push_back(crossing);
    addStats(finished, ali.stats());
    if (ali.time() < tEnd) {
      const ConsistentState cs = computeConsistentState(sys, ali.time(), ali.q(), ali.v());
      VecX y, yp;
      dae.packState(cs.q, cs.v, cs.a, cs.lambda, y, yp);
      integrator = makeIntegrator(kind, dae, ali.time(), y, yp, o);
      windowStart = IntegratorStats();
    }
  };
  // The state a crossing starts from: the integrator's last step before its failure if it
  // keeps it (and the accelerations can be computed there), else the last output.
  const auto crossingStart = [&](const SolverError& failure) {
    VecX yf;
    if (integrator->solutionAtFailure(yf) && failure.time() > last.t) {
      OutputSample s;
      s.t = failure.time();
      s.q = yf.segment(L.q, L.nq);
      s.v = yf.segment(L.v, L.nv);
      try {
        computeAccelerations(sys, s.t, s.q, s.v, s.a, s.lambda);
        if (s.q.allFinite() && s.v.allFinite() && s.a.allFinite() && s.lambda.allFinite()) return s;
      } catch (const std::exception&) {
      }
    }
    return last;
  };
  // the crossing runs on ALI3-P, which is planar (q' = v) so far
  const bool mayCross = settings.crossSingular && choice.kind != IntegratorKind::AugmentedLagrangian && L.m > 0 &&
                        sys.velocitiesAreCoordinateRates();
  int restarts = 0;  // consecutive failures just after a crossing
  try {
    while (k <= nOut) {
      try {
        for (; k <= nOut; ++k) {
          const double t = integrator->advance(outputTime(k), tEnd);
          emit(t, integrator->y().segment(L.q, L.nq), integrator->y().segment(L.v, L.nv));
          progress.update(t, totalSteps());
          regularStep = integrator->stats().lastStepSize;
          // IDA rejecting nearly every step (the order-1 trap of heavily damped elastic
          // modes, docs/formulations.md): the rest of the run with Radau IIA
          const IntegratorStats st = integrator->stats();
          const long windowSteps = st.steps - windowStart.steps;
          if (windowSteps >= kTrapWindow) {
            const long windowFailures = st.errorTestFailures - windowStart.errorTestFailures;
            if (kind == IntegratorKind::Ida && k < nOut && !o.finiteDifferenceJacobian &&
                static_cast<double>(windowFailures) >= kTrapFraction * static_cast<double>(windowSteps)) {
              summary.integratorSwitch = "at t = " + fmtTime(t) + " from ida to radau5: " +
                                         std::to_string(windowFailures) + " error-test failures in the last " +
                                         std::to_string(windowSteps) + " steps";
              const ConsistentState cs = computeConsistentState(sys, t, last.q, last.v);
              VecX y, yp;
              dae.packState(cs.q, cs.v, cs.a, cs.lambda, y, yp);
              addStats(finished, st);
              kind = IntegratorKind::Radau5;
              integrator = makeIntegrator(kind, dae, t, y, yp, o);
              windowStart = IntegratorStats();
            } else {
              windowStart = st;
            }
          }
        }
      } catch (const SolverError& e) {
        if (!mayCross || largestCoordinate > kDivergedSize * modelSize) throw;
        SingularityDiagnosis d;
        try {
          d = singularityDiagnosis(sys, last, e.time(), startRatio);
        } catch (const std::exception&) {
        }
        // a failure just after a crossing is part of it (the restart was too close to the singular position)
        const bool justRestarted = !summary.singularCrossings.empty() && integrator->stats().steps < kRestartSteps;
        if (!d.singular && d.ratio >= kCrossingTrigger * startRatio && !justRestarted) throw;
        restarts = justRestarted ? restarts + 1 : 0;
        const OutputSample start = crossingStart(e);
        addStats(finished, integrator->stats());
        integrator.reset();
        crossSingularPosition(e, d.text, start, kCrossingEndFactor * std::pow(2.0, restarts));
      }
    }
  } catch (const CrossingFailure& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.failureTime = e.time();
  } catch (const SolverError& e) {
    summary.ok = false;
    summary.message = e.what();
    summary.failureTime = e.time();
    try {
      summary.message += divergenceReport(largestCoordinate, modelSize, tOutput);
      if (!(largestCoordinate > kDivergedSize * modelSize)) {
        summary.message += singularityDiagnosis(sys, last, summary.failureTime, startRatio).text;
      }
    } catch (const std::exception&) {
      // the diagnosis is optional: IDA's reason stays the message
    }
  } catch (const RunInterrupted& e) {
    summary.ok = false;
    summary.interruptedBySignal = e.signal;
    summary.failureTime = tOutput;
    summary.message = e.what();
  } catch (const OutputWriteError& e) {
    summary.ok = false;
    summary.outputFailed = true;
    summary.failureTime = tOutput;
    summary.message = e.what();
  } catch (const NonFiniteResult& e) {
    summary.ok = false;
    summary.failureTime = tOutput;
    summary.message = std::string(e.what()) + ": the run stops before this output (the rows before it are kept)";
  } catch (const std::exception& e) {
    // an input error found during the run (exit 2) and an assembly bug keep their type;
    // a model error at an output state (ModelError, a singular matrix) is a failed run
    const bool inputError = dynamic_cast<const InputError*>(&e) && !dynamic_cast<const ModelError*>(&e);
    if (inputError || dynamic_cast<const std::logic_error*>(&e)) throw;
    // post-processing of an output state failed (e.g. a singular mass matrix after the
    // solution blew up, or an output exactly at a singular position of the mechanism,
    // where the augmented matrix for the accelerations is singular): a failure of the
    // run, reported like a solver failure
    summary.ok = false;
    summary.failureTime = integrator ? integrator->stats().currentTime : tOutput;
    summary.message = "evaluating the outputs at t = " + std::to_string(tOutput) + " failed: " + e.what();
    try {
      summary.message += divergenceReport(largestCoordinate, modelSize, tOutput);
      if (!(largestCoordinate > kDivergedSize * modelSize)) {
        summary.message += singularityDiagnosis(sys, last, tOutput, startRatio).text;
      }
    } catch (const std::exception&) {
    }
  }
  summary.stats = finished;
  if (integrator) addStats(summary.stats, integrator->stats());
  const double velocityScale = std::max(maxSpeed, modelSize / (tEnd - t0));
  if (summary.maxPositionViolation > kWarnFraction * modelSize) {
    summary.warnings.push_back("position constraints violated by up to " + num(summary.maxPositionViolation) +
                               ", more than 1e-3 of the model size " + num(modelSize) +
                               ": the results are not accurate (tighten atol and rtol)");
  }
  if (summary.maxVelocityViolation > kWarnFraction * velocityScale) {
    summary.warnings.push_back("velocity constraints violated by up to " + num(summary.maxVelocityViolation) +
                               ", more than 1e-3 of the velocity scale " + num(velocityScale) +
                               ": the results are not accurate (tighten atol and rtol)");
  }
  summary.modalParticipation = participation.result();
  for (const std::string& w : participation.warnings()) summary.warnings.push_back(w);
  summary.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  if (summary.ok) summary.message = "reached t_end";
  return summary;
}

SimulationSummary simulateKeepingFailures(const System& sys, const SolverSettings& settings,
                                          const OutputCallback& onOutput) {
  const std::clock_t start = std::clock();
  double lastDone = std::numeric_limits<double>::quiet_NaN();
  const auto cpu = [&] { return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; };
  try {
    return simulate(sys, settings, [&](const OutputSample& sample) {
      onOutput(sample);
      lastDone = sample.t;
    });
  } catch (const InputError&) {  // includes ModelError
    throw;
  } catch (const SolverError& e) {
    SimulationSummary summary;
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = e.time();
    summary.stats.lastStepSize = e.stepSize();
    summary.cpuSeconds = cpu();
    return summary;
  } catch (const std::exception& e) {
    SimulationSummary summary;
    summary.ok = false;
    summary.message = e.what();
    summary.tReached = lastDone;
    summary.cpuSeconds = cpu();
    return summary;
  }
}

}  // namespace flexmbd
