#include "sensitivity/adjoint_run.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <exception>
#include <limits>

#include <Eigen/QR>

#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/ida_solver.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_stages.hpp"
#include "simulation/run_state.hpp"

namespace flexmbd {

namespace {

/// The integral outputs of a run on its systems: g_k on the base system, its gradient in
/// (q, v) by central differences over the entries it depends on, g_p on each parameter's
/// perturbed systems, dF/dp from ResidualDifferences (shared by the outputs at a state).
class SystemIntegrals final : public IntegralOutputs {
 public:
  SystemIntegrals(const DaeSystem& dae, const std::vector<SensitivityParameter>& params,
                  const std::vector<IntegralOutput>& outputs, ResidualDifferences& derivatives, double t0,
                  const VecX& y0)
      : dae_(dae), params_(params), outputs_(outputs), derivatives_(derivatives) {
    const DaeLayout& L = dae.layout();
    q_ = y0.segment(L.q, L.nq);
    v_ = y0.segment(L.v, L.nv);
    const auto n = static_cast<Eigen::Index>(y0.size());
    dFdp_ = MatX::Zero(n, static_cast<Eigen::Index>(params.size()));
    cacheY_ = VecX::Zero(n);
    cacheYp_ = VecX::Zero(n);
    gyCache_.assign(outputs.size(), VecX::Zero(n));
    gyTime_.assign(outputs.size(), std::nan(""));
    gyY_.assign(outputs.size(), VecX::Zero(n));
    findDependencies(t0, y0);
  }
  int count() const override { return static_cast<int>(outputs_.size()); }
  int parameterCount() const override { return static_cast<int>(params_.size()); }

  void integrands(double t, const double* y, double* g) override {
    unpack(y);
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      g[k] = outputs_[k].terminal ? 0.0 : outputs_[k].integrand(dae_.system(), t, q_, v_);
    }
  }

  void integrandGradient(int k, double t, const double* y, double* gy) override {
    if (outputs_[static_cast<std::size_t>(k)].terminal) {  // its adjoint is homogeneous
      Eigen::Map<VecX>(gy, cacheY_.size()).setZero();
      return;
    }
    valueGradient(k, t, y, gy);
  }

  /// The output's value c(t, y) on the run's system.
  double value(int k, double t, const double* y) {
    unpack(y);
    return outputs_[static_cast<std::size_t>(k)].integrand(dae_.system(), t, q_, v_);
  }

  /// dc/dp_i at (t, y): the output's own dependence on parameter i (0 where it has none).
  double explicitDerivative(int k, int i, double t, const double* y) {
    const auto K = static_cast<std::size_t>(k), I = static_cast<std::size_t>(i);
    if (!explicitParameters_[K][I]) return 0.0;
    unpack(y);
    const SensitivityParameter& p = params_[I];
    // five-point difference (AbramowitzStegun1964, eq. 25.3.6), as dF/dp
    return stencilDerivative<double>(p.step, [&](int j) {
      return outputs_[K].integrand(*p.systems[static_cast<std::size_t>(j)], t, q_, v_);
    });
  }

  /// dc/dy of output k's integrand (its value for a terminal output) at (t, y) into gy.
  void valueGradient(int k, double t, const double* y, double* gy) {
    const auto K = static_cast<std::size_t>(k);
    const auto n = static_cast<Eigen::Index>(cacheY_.size());
    const Eigen::Map<const VecX> Y(y, n);
    if (!(t == gyTime_[K] && Y == gyY_[K])) {
      unpack(y);
      VecX& out = gyCache_[K];
      out.setZero();
      for (const int j : dependencies_[K]) out[j] = difference(k, t, j);
      gyTime_[K] = t;
      gyY_[K] = Y;
    }
    Eigen::Map<VecX>(gy, n) = gyCache_[K];
  }

  void gradientIntegrand(int k, double t, const double* y, const double* yp, const double* lambda,
                         double* out) override {
    const auto n = static_cast<Eigen::Index>(cacheY_.size());
    const Eigen::Map<const VecX> Y(y, n), Yp(yp, n), Lambda(lambda, n);
    if (!(cacheValid_ && t == cacheT_ && Y == cacheY_ && Yp == cacheYp_)) {
      for (int i = 0; i < parameterCount(); ++i) derivatives_.residualDerivative(i, t, y, yp, dFdp_.col(i).data());
      cacheT_ = t;
      cacheY_ = Y;
      cacheYp_ = Yp;
      cacheValid_ = true;
    }
    const bool terminal = outputs_[static_cast<std::size_t>(k)].terminal;
    for (int i = 0; i < parameterCount(); ++i) {
      // g_p - lambda^T F_p (IdasGuide, "Adjoint sensitivity analysis"); g = 0 for a terminal output
      out[i] = -Lambda.dot(dFdp_.col(i)) + (terminal ? 0.0 : explicitDerivative(k, i, t, y));
    }
  }

 private:
  void unpack(const double* y) {
    const DaeLayout& L = dae_.layout();
    q_ = Eigen::Map<const VecX>(y + L.q, L.nq);
    v_ = Eigen::Map<const VecX>(y + L.v, L.nv);
  }
  /// The step of entry j of y: eps^(1/3) max(|y_j|, 1) (three-point difference).
  static double stepOf(double value) {
    return stepTaken(value, kCentralDifferenceFraction * std::max(std::fabs(value), 1.0));
  }
  /// dg_k/dy_j by a central difference at the unpacked state (restored after).
  double difference(int k, double t, int j) {
    const DaeLayout& L = dae_.layout();
    const bool isQ = j < L.q + L.nq;
    double& entry = isQ ? q_[j - L.q] : v_[j - L.v];
    const double saved = entry, h = stepOf(saved);
    const System& sys = dae_.system();
    const auto& g = outputs_[static_cast<std::size_t>(k)].integrand;
    entry = saved + h;
    const double plus = g(sys, t, q_, v_);
    entry = saved - h;
    const double minus = g(sys, t, q_, v_);
    entry = saved;
    return (plus - minus) / (2.0 * h);
  }
  /// Which entries of (q, v) each integrand depends on and which parameters it holds
  /// explicitly: those that change it, bit for bit, at the initial state or at a generic
  /// state near it (as ResidualDifferences finds the bodies of a parameter).
  void findDependencies(double t0, const VecX& y0) {
    const DaeLayout& L = dae_.layout();
    std::vector<VecX> states{y0, y0};
    for (Eigen::Index k = 0; k < y0.size(); ++k) {
      states[1][k] += 1e-2 * std::sin(1.0 + 0.7548776662 * static_cast<double>(k)) * (1.0 + std::fabs(y0[k]));
    }
    dependencies_.assign(outputs_.size(), {});
    explicitParameters_.assign(outputs_.size(), std::vector<char>(params_.size(), 0));
    const System& sys = dae_.system();
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      const auto& g = outputs_[k].integrand;
      for (int j = 0; j < L.nq + L.nv; ++j) {
        const int entry = j < L.nq ? L.q + j : L.v + (j - L.nq);
        bool depends = false;
        for (const VecX& y : states) {
          unpack(y.data());
          const double base = g(sys, t0, q_, v_);
          double& e = j < L.nq ? q_[j] : v_[j - L.nq];
          e += stepOf(e);
          depends = depends || !(g(sys, t0, q_, v_) == base);
        }
        if (depends) dependencies_[k].push_back(entry);
      }
      for (std::size_t i = 0; i < params_.size(); ++i) {
        for (const VecX& y : states) {
          unpack(y.data());
          if (!(g(*params_[i].systems[0], t0, q_, v_) == g(*params_[i].systems[1], t0, q_, v_))) {
            explicitParameters_[k][i] = 1;
          }
        }
      }
    }
  }

  const DaeSystem& dae_;
  const std::vector<SensitivityParameter>& params_;
  const std::vector<IntegralOutput>& outputs_;
  ResidualDifferences& derivatives_;
  VecX q_, v_;
  std::vector<std::vector<int>> dependencies_;
  std::vector<std::vector<char>> explicitParameters_;
  // dF/dp at (cacheT_, cacheY_, cacheYp_), shared by the outputs
  MatX dFdp_;
  VecX cacheY_, cacheYp_;
  double cacheT_ = 0.0;
  bool cacheValid_ = false;
  // g_y per output at (gyTime_, gyY_): the backward corrector evaluates it several times at one state
  std::vector<VecX> gyCache_, gyY_;
  std::vector<double> gyTime_;
};

/// Dense F_y = J(0) and E = J(1) - J(0) of the DAE at a state.
void denseJacobians(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, MatX& Fy, MatX& E) {
  const int n = dae.size();
  Fy = MatX::Zero(n, n);
  E = MatX::Zero(n, n);
  JacobianSink s0 = JacobianSink::dense(Fy.data(), n);
  dae.jacobian(t, y.data(), yp.data(), 0.0, s0);
  JacobianSink s1 = JacobianSink::dense(E.data(), n);
  dae.jacobian(t, y.data(), yp.data(), 1.0, s1);
  E -= Fy;
}

}  // namespace

namespace {

/// The GGL layout [q, v, lambda, mu] the adjoint's terminal values are derived for.
void requireGglLayout(const DaeLayout& L) {
  if (L.mu < 0 || L.q != 0 || L.v != L.nq || L.lambda != L.nq + L.nv) {
    throw std::logic_error("adjoint terminal values: the GGL layout [q, v, lambda, mu] expected");
  }
}

/// Whether the multiplier column nd + j of F_y has entries in the constraint rows (the
/// row lambda_k = 0 or mu_k = 0 of a released equation).
bool releasedColumn(const MatX& Fy, int nd, int j) {
  const int na = static_cast<int>(Fy.rows()) - nd;
  return Fy.col(nd + j).tail(na).cwiseAbs().maxCoeff() > 0.0;
}

}  // namespace

MatX adjointTerminalValues(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const VecX& gy,
                           const VecX& lambdaD) {
  const DaeLayout& L = dae.layout();
  requireGglLayout(L);
  MatX Fy, E;
  denseJacobians(dae, t, y, yp, Fy, E);
  const int nd = L.nq + L.nv, na = L.size - nd;
  const bool moving = lambdaD.size() == nd && lambdaD.cwiseAbs().maxCoeff() > 0.0;
  // the rates of F_y and E along the motion, (X(y + e y') - X(y - e y')) / (2 e) (central
  // difference, NocedalWright2006, sec. 8.1): the terms (dE/dt)^T lambda_D and the
  // derivatives of the algebraic rows (d/dt F_Da)^T lambda_D; not needed at lambda_D = 0
  MatX FyRate = MatX::Zero(L.size, L.size), ERate = MatX::Zero(L.size, L.size);
  if (moving && yp.cwiseAbs().maxCoeff() > 0.0) {
    const double e = kCentralDifferenceFraction * std::max(1.0, y.cwiseAbs().maxCoeff()) / yp.cwiseAbs().maxCoeff();
    MatX FyPlus, EPlus, FyMinus, EMinus;
    denseJacobians(dae, t + e, y + e * yp, yp, FyPlus, EPlus);
    denseJacobians(dae, t - e, y - e * yp, yp, FyMinus, EMinus);
    FyRate = (FyPlus - FyMinus) / (2.0 * e);
    ERate = (EPlus - EMinus) / (2.0 * e);
  }
  const VecX lD = moving ? lambdaD : VecX::Zero(nd);
  // unknowns x = [lambda_D' (nd); lambda_A (na)] at the given lambda_D
  MatX A = MatX::Zero(L.size, L.size);
  VecX b = VecX::Zero(L.size);
  // differential rows of E^T lambda' + (dE/dt)^T lambda - F_y^T lambda + g_y = 0 (CaoLiPetzoldSerban2003)
  A.topLeftCorner(nd, nd) = E.topLeftCorner(nd, nd).transpose();
  A.topRightCorner(nd, na) = -Fy.bottomLeftCorner(na, nd).transpose();
  b.head(nd) = -gy.head(nd) - ERate.topLeftCorner(nd, nd).transpose() * lD + Fy.topLeftCorner(nd, nd).transpose() * lD;
  // algebraic rows: -F_Da^T lambda_D - F_Aa^T lambda_A + g_a = 0 (g holds no multiplier); where
  // F_Aa's column is empty (a constraint not released) its derivative, the hidden
  // constraint F_Da^T lambda_D' + (d/dt F_Da)^T lambda_D = 0; where not (a released
  // equation's row lambda_k = 0) the row itself, F_Aa^T lambda_A = -F_Da^T lambda_D
  for (int j = 0; j < na; ++j) {
    const auto column = Fy.col(nd + j);
    if (releasedColumn(Fy, nd, j)) {
      A.row(nd + j).tail(na) = column.tail(na).transpose();
      b[nd + j] = -column.head(nd).dot(lD);
    } else {
      A.row(nd + j).head(nd) = column.head(nd).transpose();
      b[nd + j] = -FyRate.col(nd + j).head(nd).dot(lD);
    }
  }
  const VecX x = Eigen::CompleteOrthogonalDecomposition<MatX>(A).solve(b);
  MatX out = MatX::Zero(L.size, 2);
  out.col(0).head(nd) = lD;
  out.col(0).tail(na) = x.tail(na);
  out.col(1).head(nd) = x.head(nd);
  return out;
}

TerminalAdjoint terminalAdjoint(const DaeSystem& dae, double t, const VecX& y, const VecX& yp, const VecX& cy) {
  const DaeLayout& L = dae.layout();
  requireGglLayout(L);
  MatX Fy, E;
  denseJacobians(dae, t, y, yp, Fy, E);
  const int nd = L.nq + L.nv, na = L.size - nd;
  // c_D = E_DD^T lambda_D + F_AD^T nu (CaoLiPetzoldSerban2003) with lambda_D on the adjoint's algebraic rows
  // (F_Da^T lambda_D = 0 where no equation is released; a released row's nu = 0): then
  // c_D s_D = lambda_D^T E s_D - nu^T F_Ap for every consistent s (F_AD s_D + F_Ap = 0)
  MatX A = MatX::Zero(L.size, L.size);
  VecX b = VecX::Zero(L.size);
  A.topLeftCorner(nd, nd) = E.topLeftCorner(nd, nd).transpose();
  A.topRightCorner(nd, na) = Fy.bottomLeftCorner(na, nd).transpose();
  b.head(nd) = cy.head(nd);
  for (int j = 0; j < na; ++j) {
    if (releasedColumn(Fy, nd, j)) {
      A(nd + j, nd + j) = 1.0;  // the released row's nu (its row of F_AD is empty)
    } else {
      A.row(nd + j).head(nd) = Fy.col(nd + j).head(nd).transpose();
    }
  }
  const VecX x = Eigen::CompleteOrthogonalDecomposition<MatX>(A).solve(b);
  TerminalAdjoint out;
  const MatX values = adjointTerminalValues(dae, t, y, yp, VecX::Zero(L.size), x.head(nd));
  out.lambda = values.col(0);
  out.rate = values.col(1);
  out.nu = VecX::Zero(L.size);
  out.nu.tail(na) = x.tail(na);
  return out;
}

namespace {

/// The absolute tolerances of the adjoint of an output of size G (docs/sensitivities.md):
/// lambda_q = dG/dq(t) and M lambda_v = dG/dv(t) (the output's derivative with respect to
/// the state at t) are held to rtol |G| over the state's scale of each entry, atol_j / rtol
/// (the run's own tolerances), velocities' over the mass diagonal too; the adjoint
/// multipliers (out of the error test) likewise.
VecX adjointTolerances(const DaeLayout& L, const VecX& atol, double rtol, const MatX& E, double value) {
  const double g = std::max(std::fabs(value), std::numeric_limits<double>::min() / rtol);
  VecX out(atol.size());
  for (Eigen::Index j = 0; j < atol.size(); ++j) {
    const double scale = atol[j] / rtol;  // the state's scale of entry j
    const bool velocity = j >= L.v && j < L.v + L.nv;
    const double mass = velocity && E(j, j) > 0.0 ? E(j, j) : 1.0;
    out[j] = rtol * g / (scale * mass);
  }
  return out;
}

/// Memory of one recording: IDAS keeps one vector of the DAE's size per step.
constexpr double kRecordingBytes = 512.0 * 1024 * 1024;
/// The steps one recording may store within kRecordingBytes.
long recordingSteps(const DaeSystem& dae) {
  return std::max(1L, static_cast<long>(kRecordingBytes / (8.0 * dae.size())));
}
/// The fraction of the run a pilot integrates to estimate its steps (recordingStore).
constexpr double kPilotFraction = 0.05;
/// Steps added to every estimate of a store.
constexpr long kRecordingExtraSteps = 500;

/// The store of the run's own recording: IDAS allocates it whole at the start (a vector
/// per step, about 2 us each: 0.2 s for 1e5 steps), and a run that outgrows it is recorded
/// again (recordAgain). A plain pilot over the first kPilotFraction of the run counts its
/// steps; the store holds twice their extrapolation (a start takes the smallest steps, so
/// this errs high), within the memory of one recording.
long recordingStore(const DaeSystem& dae, const IntegratorOptions& options, const RunStart& start, double t0,
                    double tEnd) {
  IdaSolver pilot(dae, t0, start.y0, start.yp0, options);
  const double tPilot = t0 + kPilotFraction * (tEnd - t0);
  try {
    pilot.advance(tPilot, tPilot);
  } catch (const SolverError&) {  // the run itself will say why
  }
  const double estimate = 2.0 * static_cast<double>(pilot.stats().steps) / kPilotFraction + kRecordingExtraSteps;
  return std::min(recordingSteps(dae), static_cast<long>(estimate));
}

/// A model without a degree of freedom (G v = -g_t fixes every velocity: a kinematically
/// driven mechanism) has lambda_q = lambda_v = 0: its adjoint is all algebraic, IDAS's error
/// estimates vanish and its backward steps stay at order 1, so the gradients carry errors
/// of about sqrt(rtol) (measured on the driven rigid slider crank: 6e-3, 6e-4, 6e-5 at rtol
/// 1e-7, 1e-9, 1e-11). The warning for such a model ("" for others).
std::string algebraicAdjointWarning(const System& sys, const DaeSystem& dae, const ConsistentState& init, double t0) {
  if (dae.layout().m == 0) return "";
  MatX G;
  evaluateConstraints(sys, init.q, t0, nullptr, &G);
  const Eigen::Index freedom = G.cols() - Eigen::CompleteOrthogonalDecomposition<MatX>(G).rank();
  if (freedom > 0) return "";
  return "adjoint: the model has no degree of freedom (its constraints and drivers fix every velocity): its adjoint "
         "is algebraic and IDAS integrates it back at order 1, so the gradients carry errors of about sqrt(rtol) "
         "(docs/sensitivities.md); the forward sensitivities (--sensitivity without --adjoint) are exact there";
}

/// Stage "record again": the run from t0 once more, as one recording whose store holds
/// twice the steps the run took (four times more if it took more still), up to
/// kRecordingBytes. Only the first checkpoint's interval is recomputed exactly by IDAS (a restored
/// later checkpoint takes a fresh Jacobian where the first pass had an older one, and IDAS
/// 6.4 overran its step store when that took more steps: SUNDIALS issue 49). Recording the
/// backward pass in segments from the run's outputs was tried: a recording restarted mid-run
/// made the adjoint's corrector fail in its first steps.
/// @throws SolverError if the run needs more memory than one recording may take.
std::unique_ptr<IdaSolver> recordAgain(const DaeSystem& dae, const IntegratorOptions& options, SystemIntegrals& integrals,
                                       const RunStart& start, double t0, double tEnd, long runSteps) {
  const long limit = recordingSteps(dae);
  for (long store = std::min(limit, 2 * runSteps + kRecordingExtraSteps);; store = std::min(limit, 4 * store)) {
    auto recording = std::make_unique<IdaSolver>(dae, t0, start.y0, start.yp0, options, integrals, store);
    recording->advance(tEnd, tEnd);
    if (recording->checkpoints() <= 1) return recording;
    if (store >= limit) {
      throw SolverError("adjoint: the run's " + std::to_string(runSteps) + " steps of " + std::to_string(dae.size()) +
                            " unknowns need more than the " +
                            std::to_string(static_cast<long>(kRecordingBytes / 1048576)) +
                            " MiB one recording may take: shorten the run (t_end) or loosen rtol",
                        t0, 0.0);
    }
  }
}

}  // namespace

AdjointSummary simulateWithAdjoint(const System& sys, const std::vector<SensitivityParameter>& params,
                                   const std::vector<IntegralOutput>& outputs, const SolverSettings& given,
                                   const OutputCallback& onOutput, long recordingStoreSteps) {
  if (params.empty()) throw InputError("adjoint sensitivities: no parameter given");
  if (outputs.empty()) throw InputError("adjoint sensitivities: no integral output given");
  const SolverSettings settings = sensitivityRunSettings(given, "adjoint sensitivities");
  if (settings.formulation != Formulation::Ggl) {
    throw InputError("solver.formulation: adjoint sensitivities are derived for the GGL form: expected \"ggl\", got \"" +
                     toString(settings.formulation) + "\"");
  }
  const std::clock_t cpuStart = std::clock();
  const double t0 = settings.tStart, tEnd = settings.tEnd;

  // start: the consistent state, the perturbed DAEs, the initial sensitivities (the
  // gradient's term lambda(t0)^T E s(t0))
  const SensitivityStart begin = startSensitivityRun(sys, settings, params);
  const ConsistentState& init = begin.init;
  const DaeSystem& dae = *begin.dae;
  const PerturbedDaes& perturbed = begin.perturbed;
  const InitialSensitivities s0 = initialSensitivities(dae, perturbed.stencils, init, t0);
  const RunStart start = startRun(dae, init, t0);

  AdjointSummary out;
  OutputRecorder recorder(sys, start.modelSize, onOutput, dae.releasedEquations());
  if (const std::optional<RunFailure> stop = recordInitialOutput(recorder, dae.layout(), start, t0)) {
    out.run = summaryAtStart(start, recorder.recorded(), *stop);
    return out;
  }
  const ModelScales modelScale = modelScales(sys, init.v, t0, tEnd);
  ChosenIntegrator choice = chooseIntegratorOptions(sys, dae, settings, &modelScale);
  choice.reason = "adjoint sensitivities are computed by IDAS";

  // forward: the run, with the outputs' integrals, recorded for the backward pass on the
  // way (one checkpoint: IDAS's recomputation repeats this pass exactly)
  ResidualDifferences derivatives(perturbed.stencils, t0, start.y0, start.yp0);
  SystemIntegrals integrals(dae, params, outputs, derivatives, t0, start.y0);
  RunState state;
  state.kind = IntegratorKind::Ida;
  const long store =
      recordingStoreSteps > 0 ? recordingStoreSteps : recordingStore(dae, choice.options, start, t0, tEnd);
  auto ida = std::make_unique<IdaSolver>(dae, t0, start.y0, start.yp0, choice.options, integrals, store);
  IdaSolver& solver = *ida;
  state.usedKlu = solver.usesKlu();
  state.integrator = std::move(ida);
  const OutputSchedule schedule(t0, tEnd, settings.outputStep);
  ProgressReporter progress(settings.progress, t0, tEnd, "ida+adjoint");
  const RunContext ctx{sys, dae, settings, choice.options, schedule, start.modelSize, start.startRatio, false};
  const std::optional<RunFailure> failure = integrateOnOneIntegrator(ctx, state, recorder, progress);
  out.run = finishSummary(start, recorder.recorded(), choice, state, failure, tEnd - t0);
  for (const int r : dae.releasedEquations()) out.run.redundantConstraints.push_back(sys.describeEquation(r));
  out.run.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  if (!out.run.ok) return out;

  // backward: one adjoint per output from its terminal values at T
  const std::clock_t backwardStart = std::clock();
  if (const std::string w = algebraicAdjointWarning(sys, dae, init, t0); !w.empty()) out.run.warnings.push_back(w);
  const VecX G = solver.integrals();
  try {
    std::unique_ptr<IdaSolver> again;
    IdaSolver& recording =
        solver.checkpoints() <= 1
            ? solver
            : *(again = recordAgain(dae, choice.options, integrals, start, t0, tEnd, solver.stats().steps));
    out.recordedAgain = again != nullptr;
    const DaeLayout& L = dae.layout();
  const int n = dae.size(), count = static_cast<int>(outputs.size());
    const auto np = static_cast<Eigen::Index>(params.size());
    AdjointProblem problem{&integrals, MatX(n, count), MatX(n, count), MatX(n, count), MatX(np, count), L.nq};
    MatX FyT, ET;
    denseJacobians(dae, tEnd, recording.y(), recording.yp(), FyT, ET);
    VecX gy(n);
    std::vector<TerminalAdjoint> terminal;
    for (int k = 0; k < count; ++k) {
      double size = G[k];  // the output's size, the scale of its adjoint's tolerances
      if (outputs[static_cast<std::size_t>(k)].terminal) {
        integrals.valueGradient(k, tEnd, recording.y().data(), gy.data());
        terminal.push_back(terminalAdjoint(dae, tEnd, recording.y(), recording.yp(), gy));
        problem.lambdaT.col(k) = terminal.back().lambda;
        problem.lambdaTp.col(k) = terminal.back().rate;
        // |c(T)| and its change over the state's scales (atol_j / rtol): a column that is 0
        // at T still has the size of its motion
        size = std::fabs(integrals.value(k, tEnd, recording.y().data())) +
               gy.cwiseAbs().dot(choice.options.atol) / choice.options.rtol;
      } else {
        integrals.integrandGradient(k, tEnd, recording.y().data(), gy.data());
        terminal.emplace_back();
        const MatX values = adjointTerminalValues(dae, tEnd, recording.y(), recording.yp(), gy, VecX());
        problem.lambdaT.col(k) = values.col(0);
        problem.lambdaTp.col(k) = values.col(1);
      }
      problem.atolB.col(k) = adjointTolerances(L, choice.options.atol, choice.options.rtol, ET, size);
      const double g = std::max(std::fabs(size), std::numeric_limits<double>::min() / choice.options.rtol);
      // each gradient to rtol |G| / |p_i| (the change of G over a relative change of p_i of 1)
      for (Eigen::Index i = 0; i < np; ++i) problem.atolQ(i, k) = choice.options.rtol * g / perturbed.scales[i];
    }
    ProgressReporter backwardProgress(settings.progress, t0, tEnd, "ida adjoint, backward", true);
    std::function<void(double, long)> report;  // none where nothing is shown
    if (backwardProgress.enabled()) report = [&](double t, long steps) { backwardProgress.update(t, steps); };
    const AdjointSolution backward = recording.integrateAdjoint(problem, t0, report);
    // dG/dp = int (g_p - lambda^T F_p) dt + lambda(t0)^T E(t0) s(t0) (IdasGuide, "Adjoint sensitivity analysis")
    MatX Fy0, E0;
    denseJacobians(dae, t0, start.y0, start.yp0, Fy0, E0);
    for (int k = 0; k < count; ++k) {
      IntegralGradient r{outputs[static_cast<std::size_t>(k)].name, G[k], backward.integral.col(k)};
      r.gradient += (backward.lambda0.col(k).transpose() * E0 * s0.s0).transpose();
      if (outputs[static_cast<std::size_t>(k)].terminal) {
        // dc(T)/dp = c_p - nu^T F_p(T) + the adjoint's part above (terminalAdjoint; CaoLiPetzoldSerban2003)
        r.value = integrals.value(k, tEnd, recording.y().data());
        VecX Fp(n);
        for (Eigen::Index i = 0; i < np; ++i) {
          derivatives.residualDerivative(static_cast<int>(i), tEnd, recording.y().data(), recording.yp().data(),
                                         Fp.data());
          r.gradient[i] += integrals.explicitDerivative(k, static_cast<int>(i), tEnd, recording.y().data()) -
                           terminal[static_cast<std::size_t>(k)].nu.dot(Fp);
        }
      }
      if (const auto& report = outputs[static_cast<std::size_t>(k)].report) report(tEnd - t0, r.value, r.gradient);
      out.outputs.push_back(std::move(r));
    }
    out.backwardOk = true;
    out.backwardSteps = backward.steps;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    out.backwardMessage = e.what();
  }
  out.backwardCpuSeconds = static_cast<double>(std::clock() - backwardStart) / CLOCKS_PER_SEC;
  out.run.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;  // the whole: forward and backward
  return out;
}

}  // namespace flexmbd
