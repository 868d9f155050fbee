#include "sensitivity/sensitivity_run.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <exception>
#include <limits>

#include <Eigen/QR>

#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/ida_solver.hpp"
#include "simulation/output_recorder.hpp"
#include "simulation/run_stages.hpp"
#include "simulation/run_state.hpp"

namespace flexmbd {

double parameterStep(double p, double typical) {
  return stepTaken(p, kParameterStepFraction * (p != 0.0 ? std::fabs(p) : typical));
}

MatX sensitivityTolerances(const VecX& atol, double frameAtol, double modelSize, const VecX& scales) {
  const double factor = std::max(1.0, kSensitivityNoiseFloor * modelSize / frameAtol);
  MatX out(atol.size(), scales.size());
  for (Eigen::Index i = 0; i < scales.size(); ++i) out.col(i) = atol * (factor / std::fabs(scales[i]));
  return out;
}

// ----- dF/dp by five-point differences of the perturbed residuals ---------------------

namespace {

bool any(const ResidualParts& p) {
  const auto set = [](const std::vector<char>& v) { return std::find(v.begin(), v.end(), 1) != v.end(); };
  return set(p.bodies) || set(p.forces) || set(p.constraints);
}

/// Which terms of the systems of `p` can differ (ResidualDifferences): those of time, and
/// those of the state whose terms differ between the systems at p + h and p - h at one of
/// the test states; and whether the latter are linear in p there.
ResidualDifferences::Split splitParts(const ResidualDifferences::Stencil& p, double t0, const std::vector<VecX>& ys,
                                      const std::vector<VecX>& yps,
                                      const std::array<std::unique_ptr<DaeScratch>, kStencilPoints>& scratch) {
  const System& sys = p.daes[0]->system();
  const auto n = static_cast<Eigen::Index>(p.daes[0]->size());
  std::array<VecX, kStencilPoints> F;
  for (VecX& f : F) f = VecX(n);
  const auto evaluate = [&](const ResidualParts& parts, const VecX& y, const VecX& yp, int points) {
    for (int j = 0; j < points; ++j) {
      const auto J = static_cast<std::size_t>(j);
      p.daes[J]->residualOfParts(t0, y.data(), yp.data(), F[J].data(), parts, *scratch[J]);
    }
  };
  // the terms of the state that differ (bit-identical terms cancel; NaN never compares equal: kept)
  ResidualParts time = ResidualParts::none(sys), state = ResidualParts::none(sys);
  const auto differs = [&](const ResidualParts& one) {
    for (std::size_t k = 0; k < ys.size(); ++k) {
      evaluate(one, ys[k], yps[k], 2);
      if (!(F[0].array() == F[1].array()).all()) return true;
    }
    return false;
  };
  ResidualParts one = ResidualParts::none(sys);
  const auto classify = [&](std::vector<char>& flag, std::vector<char>& timeFlag, std::vector<char>& stateFlag,
                            std::size_t k, bool ofTime) {
    if (ofTime) {
      timeFlag[k] = 1;
      return;
    }
    flag[k] = 1;
    if (differs(one)) stateFlag[k] = 1;
    flag[k] = 0;
  };
  for (int b = 0; b < sys.numBodies(); ++b) {
    classify(one.bodies, time.bodies, state.bodies, static_cast<std::size_t>(b), false);
  }
  for (int c = 0; c < sys.numConstraints(); ++c) {
    classify(one.constraints, time.constraints, state.constraints, static_cast<std::size_t>(c),
             sys.constraintIsDriver(ConstraintIndex(c)));
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    classify(one.forces, time.forces, state.forces, static_cast<std::size_t>(f), sys.force(ForceIndex(f)).dependsOnTime());
  }
  // linear in p: the two-point differences at p +- h and p +- 2 h agree to their round-off
  // on every row at every test state
  bool linear = any(state);
  const double h = p.step, kRoundOffs = 8.0 * std::numeric_limits<double>::epsilon();
  for (std::size_t k = 0; k < ys.size() && linear; ++k) {
    evaluate(state, ys[k], yps[k], kStencilPoints);
    for (Eigen::Index r = 0; r < n && linear; ++r) {
      const double inner = (F[0][r] - F[1][r]) / (2.0 * h), outer = (F[2][r] - F[3][r]) / (4.0 * h);
      const double size = std::fabs(F[0][r]) + std::fabs(F[1][r]) + std::fabs(F[2][r]) + std::fabs(F[3][r]);
      linear = std::fabs(inner - outer) <= kRoundOffs * size / h;  // false for NaN
    }
  }
  ResidualDifferences::Split out;
  out.all = ResidualParts::none(sys);
  for (const auto member : {&ResidualParts::bodies, &ResidualParts::forces, &ResidualParts::constraints}) {
    for (std::size_t k = 0; k < (out.all.*member).size(); ++k) {
      (out.all.*member)[k] = static_cast<char>((time.*member)[k] || (state.*member)[k]);
    }
  }
  out.stencil = linear ? time : out.all;
  out.pair = linear ? state : ResidualParts::none(sys);
  out.anyStencil = any(out.stencil);
  out.anyPair = any(out.pair);
  return out;
}

}  // namespace

ResidualDifferences::ResidualDifferences(std::vector<Stencil> stencils, double t0, const VecX& y0, const VecX& yp0)
    : stencils_(std::move(stencils)) {
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
  for (const Stencil& p : stencils_) {
    std::array<std::unique_ptr<DaeScratch>, kStencilPoints> scratch;
    for (std::size_t j = 0; j < kStencilPoints; ++j) scratch[j] = p.daes[j]->makeScratch();
    parts_.push_back(splitParts(p, t0, ys, yps, scratch));
    scratch_.push_back(std::move(scratch));
  }
  if (!stencils_.empty()) term_ = VecX::Zero(stencils_.front().daes[0]->size());
}

void ResidualDifferences::residualDerivative(int i, double t, const double* y, const double* yp, double* dFdp) {
  const auto k = static_cast<std::size_t>(i);
  const Stencil& p = stencils_[k];
  const Split& parts = parts_[k];
  Eigen::Map<VecX> d(dFdp, term_.size());
  d.setZero();
  // the terms that differ (the others cancel exactly in the differences):
  // sum_j w_j F(p + o_j h) / h + O(h^4) (five-point difference, AbramowitzStegun1964, eq. 25.3.6)
  for (std::size_t j = 0; j < kStencilPoints && parts.anyStencil; ++j) {
    p.daes[j]->residualOfParts(t, y, yp, term_.data(), parts.stencil, *scratch_[k][j]);
    d += (kStencilWeights[j] / p.step) * term_;
  }
  // and the terms linear in p: (F(p + 2h) - F(p - 2h)) / (4 h), exact for them
  for (std::size_t j = 2; j < kStencilPoints && parts.anyPair; ++j) {
    p.daes[j]->residualOfParts(t, y, yp, term_.data(), parts.pair, *scratch_[k][j]);
    d += ((kStencilOffsets[j] > 0.0 ? 1.0 : -1.0) / (4.0 * p.step)) * term_;  // the points p + 2h, p - 2h
  }
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

InitialSensitivities initialSensitivities(const DaeSystem& base, const std::vector<ResidualDifferences::Stencil>& stencils,
                                          const ConsistentState& init, double t0) {
  const int n = base.size();
  InitialSensitivities s{MatX::Zero(n, static_cast<Eigen::Index>(stencils.size())),
                         MatX::Zero(n, static_cast<Eigen::Index>(stencils.size()))};
  const ReleasedEquations released{false, init.released};
  for (std::size_t i = 0; i < stencils.size(); ++i) {
    std::array<VecX, kStencilPoints> y, yp;
    for (std::size_t j = 0; j < kStencilPoints; ++j) {
      const DaeSystem& dae = *stencils[i].daes[j];
      const System& sys = dae.system();
      // the perturbed system's own consistent state from its own initial values (q0(p), v0(p))
      const ConsistentState c = computeConsistentState(sys, t0, sys.initialCoordinates(), sys.initialVelocities(), released);
      dae.packState(c.q, c.v, c.a, c.lambda, y[j], yp[j]);
    }
    // s0 = dy0/dp, s0' = dy0'/dp: five-point differences (AbramowitzStegun1964, eq. 25.3.6)
    // of the consistent initialisation (docs/sensitivities.md, "Consistent initial sensitivities")
    const double h = stencils[i].step;
    s.s0.col(static_cast<Eigen::Index>(i)) = stencilDerivative<VecX>(h, [&](int j) { return y[static_cast<std::size_t>(j)]; });
    s.sp0.col(static_cast<Eigen::Index>(i)) = stencilDerivative<VecX>(h, [&](int j) { return yp[static_cast<std::size_t>(j)]; });
  }
  projectOntoConstraints(base, stencils, init, t0, s.s0);
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

void projectOntoConstraints(const DaeSystem& base, const std::vector<ResidualDifferences::Stencil>& stencils,
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
  VecX F(L.size), r(L.size);
  for (std::size_t i = 0; i < stencils.size(); ++i) {
    auto col = s0.col(static_cast<Eigen::Index>(i));
    // dF/dp at the base state: the constraint rows of F_y s + F_p, which must vanish
    const VecX dFdp = stencilDerivative<VecX>(stencils[i].step, [&](int j) {
      stencils[i].daes[static_cast<std::size_t>(j)]->residual(t0, y.data(), yp.data(), F.data());
      return F;
    });
    const auto residualOfRows = [&](int row0) {
      r.setZero();
      addPatternProduct(P, J0.data(), col.data(), r.data());
      return VecX(r.segment(row0, L.m) + dFdp.segment(row0, L.m));
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
    PerturbedSamples samples;
    for (std::size_t j = 0; j < kStencilPoints; ++j) {
      const double e = kStencilOffsets[j] * params[i].step;
      samples.at[j] = perturbedSample(*params[i].systems[j], base.t, base.q + e * out.q.col(c), base.v + e * out.v.col(c),
                                      released);
    }
    out.perturbed.push_back(std::move(samples));
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
    ResidualDifferences::Stencil stencil{{}, p.step};
    for (std::size_t j = 0; j < kStencilPoints; ++j) {
      const System* s = p.systems[j];
      if (!s || !s->isFinalized()) throw InputError("sensitivity parameter '" + p.name + "': no finalized system");
      out.daes.push_back(std::make_unique<DaeSystem>(*s, base.formulation(), defaultStabilisationMetric(*s),
                                                     base.releasedEquations()));
      requireSameStructure(base, *out.daes.back(), p.name);
      stencil.daes[j] = out.daes.back().get();
    }
    out.stencils.push_back(stencil);
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
  const std::vector<ResidualDifferences::Stencil>& stencils = begin.perturbed.stencils;
  const VecX& scales = begin.perturbed.scales;
  const InitialSensitivities s0 = initialSensitivities(dae, stencils, init, t0);
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
  ResidualDifferences derivatives(stencils, t0, start.y0, start.yp0);
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
