#include "integrators/sensitivity_run.hpp"

#include <cmath>
#include <ctime>
#include <exception>

#include <Eigen/QR>

#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/ida_solver.hpp"
#include "integrators/output_recorder.hpp"
#include "integrators/run_stages.hpp"
#include "integrators/run_state.hpp"

namespace flexmbd {

double parameterStep(double p, double typical) {
  const double h = kCentralDifferenceFraction * std::max(std::fabs(p), typical);
  // the step actually taken: (p + h) - p, exact in floating point (Press et al. 2007, sec. 5.7)
  const volatile double shifted = p + h;
  return shifted - p;
}

MatX sensitivityTolerances(const VecX& atol, double frameAtol, double modelSize, const VecX& scales) {
  const double factor = std::max(1.0, kSensitivityNoiseFloor * modelSize / frameAtol);
  MatX out(atol.size(), scales.size());
  for (Eigen::Index i = 0; i < scales.size(); ++i) out.col(i) = atol * (factor / std::fabs(scales[i]));
  return out;
}

// ----- dF/dp by central differences of the perturbed residuals ------------------------

namespace {

/// The bodies whose residual terms differ between the systems of `p` at one of the test
/// states; all forces and constraints (they may depend on time, so agreeing at a test time
/// proves nothing).
ResidualParts differingParts(const ResidualDifferences::Pair& p, double t0, const std::vector<VecX>& ys,
                             const std::vector<VecX>& yps, DaeScratch& plusScratch, DaeScratch& minusScratch) {
  const System& sys = p.plus->system();
  ResidualParts parts = ResidualParts::none(sys);
  std::fill(parts.forces.begin(), parts.forces.end(), 1);
  std::fill(parts.constraints.begin(), parts.constraints.end(), 1);
  ResidualParts one = ResidualParts::none(sys);
  VecX Fplus(p.plus->size()), Fminus(p.plus->size());
  for (int b = 0; b < sys.numBodies(); ++b) {
    one.bodies[static_cast<std::size_t>(b)] = 1;
    for (std::size_t k = 0; k < ys.size() && !parts.bodies[static_cast<std::size_t>(b)]; ++k) {
      p.plus->residualOfParts(t0, ys[k].data(), yps[k].data(), Fplus.data(), one, plusScratch);
      p.minus->residualOfParts(t0, ys[k].data(), yps[k].data(), Fminus.data(), one, minusScratch);
      // bit-identical terms (NaN never compares equal: such a body is kept)
      if (!(Fplus.array() == Fminus.array()).all()) parts.bodies[static_cast<std::size_t>(b)] = 1;
    }
    one.bodies[static_cast<std::size_t>(b)] = 0;
  }
  return parts;
}

}  // namespace

ResidualDifferences::ResidualDifferences(std::vector<Pair> pairs, double t0, const VecX& y0, const VecX& yp0)
    : pairs_(std::move(pairs)) {
  // the test states: the initial one and every entry moved by a deterministic, irregular
  // fraction of its size (a generic state: no velocity or elastic coordinate left at zero)
  std::vector<VecX> ys{y0}, yps{yp0};
  ys.push_back(y0);
  yps.push_back(yp0);
  for (Eigen::Index k = 0; k < y0.size(); ++k) {
    const double a = std::sin(1.0 + 0.7548776662 * static_cast<double>(k));  // in (-1, 1), never repeating
    ys[1][k] += 1e-2 * a * (1.0 + std::fabs(y0[k]));
    yps[1][k] += 1e-2 * (0.5 - a) * (1.0 + std::fabs(yp0[k]));
  }
  for (const Pair& p : pairs_) {
    plusScratch_.push_back(p.plus->makeScratch());
    minusScratch_.push_back(p.minus->makeScratch());
    parts_.push_back(differingParts(p, t0, ys, yps, *plusScratch_.back(), *minusScratch_.back()));
  }
  if (!pairs_.empty()) minusResidual_ = VecX::Zero(pairs_.front().plus->size());
}

void ResidualDifferences::residualDerivative(int i, double t, const double* y, const double* yp, double* dFdp) {
  const auto k = static_cast<std::size_t>(i);
  const Pair& p = pairs_[k];
  // the terms of the parts that differ; the others cancel exactly in the difference
  p.plus->residualOfParts(t, y, yp, dFdp, parts_[k], *plusScratch_[k]);
  p.minus->residualOfParts(t, y, yp, minusResidual_.data(), parts_[k], *minusScratch_[k]);
  const auto n = minusResidual_.size();
  // dF/dp = (F(p + h) - F(p - h)) / (2 h) + O(h^2) (central difference, Nocedal & Wright 2006, sec. 8.1)
  Eigen::Map<VecX> d(dFdp, n);
  d = (d - minusResidual_) / (2.0 * p.step);
}

// ----- structure and initial sensitivities ------------------------------------------

void requireSameStructure(const DaeSystem& base, const DaeSystem& perturbed, const std::string& parameter) {
  const auto refuse = [&](const std::string& what, long a, long b) {
    throw InputError("sensitivity parameter '" + parameter + "': changing it changes " + what + " (" +
                     std::to_string(a) + " at its value, " + std::to_string(b) +
                     " a step away): expected a parameter that keeps the model's structure (a mass, a length, a "
                     "stiffness, ...; not a count of elements or modes)");
  };
  const System& a = base.system();
  const System& b = perturbed.system();
  if (a.numCoordinates() != b.numCoordinates()) refuse("the number of coordinates", a.numCoordinates(), b.numCoordinates());
  if (a.numVelocities() != b.numVelocities()) refuse("the number of velocities", a.numVelocities(), b.numVelocities());
  if (a.numConstraintEquations() != b.numConstraintEquations()) {
    refuse("the number of constraint equations", a.numConstraintEquations(), b.numConstraintEquations());
  }
  if (base.size() != perturbed.size()) refuse("the number of unknowns", base.size(), perturbed.size());
  const SparsePattern& pa = base.pattern();
  const SparsePattern& pb = perturbed.pattern();
  if (pa.colStart() != pb.colStart() || pa.rowIndex() != pb.rowIndex()) {
    refuse("the Jacobian's sparsity pattern (non-zeros)", pa.nonZeros(), pb.nonZeros());
  }
}

InitialSensitivities initialSensitivities(const DaeSystem& base, const std::vector<ResidualDifferences::Pair>& pairs,
                                          const ConsistentState& init, double t0) {
  const int n = base.size();
  InitialSensitivities s{MatX::Zero(n, static_cast<Eigen::Index>(pairs.size())),
                         MatX::Zero(n, static_cast<Eigen::Index>(pairs.size()))};
  const ReleasedEquations released{false, init.released};
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    VecX yPlus, ypPlus, yMinus, ypMinus;
    for (const auto& [dae, y, yp] : {std::tuple{pairs[i].plus, &yPlus, &ypPlus}, std::tuple{pairs[i].minus, &yMinus, &ypMinus}}) {
      const System& sys = dae->system();
      // the perturbed system's own consistent state from its own initial values (q0(p), v0(p))
      const ConsistentState c = computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities(), released);
      dae->packState(c.q, c.v, c.a, c.lambda, *y, *yp);
    }
    // s0 = dy0/dp, s0' = dy0'/dp: central differences (Nocedal & Wright 2006, sec. 8.1) of the
    // consistent initialisation (docs/sensitivities.md, "Consistent initial sensitivities")
    s.s0.col(static_cast<Eigen::Index>(i)) = (yPlus - yMinus) / (2.0 * pairs[i].step);
    s.sp0.col(static_cast<Eigen::Index>(i)) = (ypPlus - ypMinus) / (2.0 * pairs[i].step);
  }
  projectOntoConstraints(base, pairs, init, t0, s.s0);
  return s;
}

namespace {

/// Rows [r0, r0 + nr) and columns [c0, c0 + nc) of a matrix in CSC values on `p`, dense.
MatX denseBlock(const SparsePattern& p, const std::vector<double>& values, int r0, int nr, int c0, int nc) {
  MatX B = MatX::Zero(nr, nc);
  for (int c = 0; c < nc; ++c) {
    for (int64_t k = p.colStart()[c0 + c]; k < p.colStart()[c0 + c + 1]; ++k) {
      const auto r = static_cast<int>(p.rowIndex()[k]) - r0;
      if (r >= 0 && r < nr) B(r, c) = values[static_cast<std::size_t>(k)];
    }
  }
  return B;
}

}  // namespace

void projectOntoConstraints(const DaeSystem& base, const std::vector<ResidualDifferences::Pair>& pairs,
                            const ConsistentState& init, double t0, MatX& s0) {
  if (base.formulation() == Formulation::Index1) return;  // no position-level rows
  const DaeLayout& L = base.layout();
  if (L.m == 0) return;
  VecX y, yp;
  base.packState(init.q, init.v, init.a, init.lambda, y, yp);
  const SparsePattern& P = base.pattern();
  std::vector<double> J0(static_cast<std::size_t>(P.nonZeros()), 0.0);
  JacobianSink sink = JacobianSink::sparse(J0.data(), P);
  base.jacobian(t0, y.data(), yp.data(), 0.0, sink);  // dF/dy: the constraint rows hold no y'
  // F_g's rows in q (minimum-norm corrections: complete orthogonal decomposition, so a
  // released equation's empty row is no obstacle), F_gv's in v
  const Eigen::CompleteOrthogonalDecomposition<MatX> Gq(denseBlock(P, J0, L.lambda, L.m, L.q, L.nq));
  const bool ggl = L.mu >= 0;
  const Eigen::CompleteOrthogonalDecomposition<MatX> Gv(ggl ? denseBlock(P, J0, L.mu, L.m, L.v, L.nv) : MatX());
  VecX Fplus(L.size), Fminus(L.size), r(L.size);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    auto col = s0.col(static_cast<Eigen::Index>(i));
    // dF/dp at the base state: the constraint rows of F_y s + F_p, which must vanish
    pairs[i].plus->residual(t0, y.data(), yp.data(), Fplus.data());
    pairs[i].minus->residual(t0, y.data(), yp.data(), Fminus.data());
    const auto residualOfRows = [&](int row0) {
      r.setZero();
      addPatternProduct(P, J0.data(), col.data(), r.data());
      return VecX(r.segment(row0, L.m) + (Fplus - Fminus).segment(row0, L.m) / (2.0 * pairs[i].step));
    };
    // G s_q + g_p = 0 (positions), then d/dp (G v + g_t) = 0 (velocities) with the new s_q
    col.segment(L.q, L.nq) -= Gq.solve(residualOfRows(L.lambda));
    if (ggl) col.segment(L.v, L.nv) -= Gv.solve(residualOfRows(L.mu));
  }
}

// ----- the run ----------------------------------------------------------------------

namespace {

/// The sample of the system `sys` at (q, v) as the recorder makes it (accelerations and
/// multipliers from the state; minimum-norm multipliers of a released set).
OutputSample perturbedSample(const System& sys, double t, VecX q, VecX v, const std::vector<int>& released) {
  OutputSample s;
  s.t = t;
  s.q = std::move(q);
  s.v = std::move(v);
  computeAccelerations(sys, t, s.q, s.v, s.a, s.lambda, released);
  if (!released.empty()) {
    MatX G;
    evaluateConstraints(sys, s.q, t, nullptr, &G);
    s.lambda = minimumNormMultipliers(G, s.lambda);
  }
  return s;
}

/// The sensitivities of positions and velocities at an output, and the perturbed samples.
SensitivitySample sensitivitySample(const DaeLayout& L, const MatX& S, const std::vector<SensitivityParameter>& params,
                                    const OutputSample& base, const std::vector<int>& released) {
  SensitivitySample out;
  out.q = S.middleRows(L.q, L.nq);
  out.v = S.middleRows(L.v, L.nv);
  for (std::size_t i = 0; i < params.size(); ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    const double h = params[i].step;
    out.perturbed.push_back({perturbedSample(*params[i].plus, base.t, base.q + h * out.q.col(c),
                                             base.v + h * out.v.col(c), released),
                             perturbedSample(*params[i].minus, base.t, base.q - h * out.q.col(c),
                                             base.v - h * out.v.col(c), released)});
  }
  return out;
}

}  // namespace

SolverSettings sensitivityRunSettings(const SolverSettings& given, const std::string& what) {
  given.validate();
  if (given.integrator != IntegratorKind::Automatic && given.integrator != IntegratorKind::Ida) {
    throw InputError("solver.integrator: " + what + " are computed by IDAS only: expected \"ida\" or \"auto\", got \"" +
                     toString(given.integrator) + "\"");
  }
  if (given.elasticStart != ElasticStart::Given) {
    throw InputError("solver.elastic_start: " + what + " need the elastic start \"given\", got \"" +
                     toString(given.elasticStart) + "\"");
  }
  if (given.finiteDifferenceJacobian) {
    throw InputError("solver.fd_jacobian: " + what + " use the analytic Jacobian: expected false");
  }
  SolverSettings settings = given;
  settings.integrator = IntegratorKind::Ida;
  return settings;
}

PerturbedDaes perturbedDaes(const DaeSystem& base, const std::vector<SensitivityParameter>& params) {
  PerturbedDaes out;
  out.scales = VecX(static_cast<Eigen::Index>(params.size()));
  for (std::size_t i = 0; i < params.size(); ++i) {
    const SensitivityParameter& p = params[i];
    for (const System* s : {p.plus, p.minus}) {
      if (!s || !s->isFinalized()) throw InputError("sensitivity parameter '" + p.name + "': no finalized system");
      out.daes.push_back(std::make_unique<DaeSystem>(*s, base.formulation(), defaultStabilisationMetric(*s),
                                                     base.releasedEquations()));
      requireSameStructure(base, *out.daes.back(), p.name);
    }
    out.pairs.push_back({out.daes[out.daes.size() - 2].get(), out.daes.back().get(), p.step});
    out.scales[static_cast<Eigen::Index>(i)] = std::max(std::fabs(p.value), kParameterTypicalMagnitude);
  }
  return out;
}

SensitivityStart startSensitivityRun(const System& sys, const SolverSettings& settings,
                                     const std::vector<SensitivityParameter>& params) {
  ReleasedEquations released;
  released.detect = settings.redundantConstraints == RedundantConstraints::Resolve;
  SensitivityStart out;
  out.init = computeConsistentState(sys, settings.tStart, sys.initialCoordinates(), sys.initialVelocities(), released);
  out.dae = std::make_unique<DaeSystem>(sys, settings.formulation, defaultStabilisationMetric(sys), out.init.released);
  out.perturbed = perturbedDaes(*out.dae, params);
  return out;
}

SimulationSummary simulateWithSensitivities(const System& sys, const std::vector<SensitivityParameter>& params,
                                            const SolverSettings& given, const SensitivitySettings& sensitivity,
                                            const SensitivityCallback& onOutput) {
  if (params.empty()) throw InputError("sensitivities: no parameter given");
  const SolverSettings settings = sensitivityRunSettings(given, "forward sensitivities");
  const std::clock_t cpuStart = std::clock();
  const double t0 = settings.tStart, tEnd = settings.tEnd;

  // start: the consistent state, the perturbed DAEs (same structure), s0 and s0'
  const SensitivityStart begin = startSensitivityRun(sys, settings, params);
  const ConsistentState& init = begin.init;
  const DaeSystem& dae = *begin.dae;
  const std::vector<ResidualDifferences::Pair>& pairs = begin.perturbed.pairs;
  const VecX& scales = begin.perturbed.scales;
  const InitialSensitivities s0 = initialSensitivities(dae, pairs, init, t0);
  const RunStart start = startRun(dae, init, t0);

  // the outputs: the recorder's sample with the sensitivities of the state it was made from
  const MatX* currentS = &s0.s0;
  const OutputCallback withSensitivities = [&](const OutputSample& s) {
    if (onOutput) onOutput(s, sensitivitySample(dae.layout(), *currentS, params, s, dae.releasedEquations()));
  };
  OutputRecorder recorder(sys, start.modelSize, withSensitivities, dae.releasedEquations());
  if (const std::optional<RunFailure> stop = recordInitialOutput(recorder, dae.layout(), start, t0)) {
    return summaryAtStart(start, recorder.recorded(), *stop);
  }

  // choose: IDA's options as a plain run with "ida" would take them
  const ModelScales modelScale = modelScales(sys, init.v, t0, tEnd);
  ChosenIntegrator choice = chooseIntegratorOptions(sys, dae, settings, &modelScale);
  choice.reason = "forward sensitivities are computed by IDAS";

  // integrate output by output
  ResidualDifferences derivatives(pairs, t0, start.y0, start.yp0);
  const SensitivityProblem problem{&derivatives, s0.s0, s0.sp0, scales,
                                   sensitivityTolerances(choice.options.atol, choice.tolerances.position,
                                                         start.modelSize, scales),
                                   sensitivity.errorControl};
  RunState state;
  state.kind = IntegratorKind::Ida;
  auto ida = std::make_unique<IdaSolver>(dae, t0, start.y0, start.yp0, choice.options, problem);
  IdaSolver& solver = *ida;
  state.usedKlu = solver.usesKlu();
  state.integrator = std::move(ida);
  currentS = &solver.sensitivity();
  const OutputSchedule outputs(t0, tEnd, settings.outputStep);
  ProgressReporter progress(settings.progress, t0, tEnd, "ida+sensitivities");
  const RunContext ctx{sys, dae, settings, choice.options, outputs, start.modelSize, start.startRatio, false};
  const std::optional<RunFailure> failure = integrateOnOneIntegrator(ctx, state, recorder, progress);
  SimulationSummary summary = finishSummary(start, recorder.recorded(), choice, state, failure, tEnd - t0);
  for (const int r : dae.releasedEquations()) summary.redundantConstraints.push_back(sys.describeEquation(r));
  summary.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  return summary;
}

}  // namespace flexmbd
