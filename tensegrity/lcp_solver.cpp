#include "tensegrity/lcp_solver.hpp"

#include <LCP_Solvers.h>
#include <LinearComplementarityProblem.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
#include <lcp_cst.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "core/errors.hpp"

namespace flexmbd {

std::string toString(LcpMethod m) {
  switch (m) {
    case LcpMethod::Lemke: return "lemke";
    case LcpMethod::ProjectedGaussSeidel: return "pgs";
  }
  return "?";
}

LcpMethod parseLcpMethod(const std::string& name) {
  if (name == "lemke") return LcpMethod::Lemke;
  if (name == "pgs") return LcpMethod::ProjectedGaussSeidel;
  throw InputError("solver.lcp: unknown LCP solver '" + name + "' (expected one of: lemke, pgs)");
}

namespace {

struct MatrixDeleter {
  void operator()(NumericsMatrix* m) const { NM_free(m); }
};
}  // namespace

void LcpSolver::OptionsDeleter::operator()(SolverOptions* o) const {
  solver_options_delete(o);  // frees iparam, dparam, internal solvers: not o itself
  std::free(o);              // solver_options_create allocated it with malloc
}

LcpSolver::LcpSolver(const LcpOptions& options) : options_(options) {
  if (!(options_.tolerance > 0.0)) throw InputError("solver.lcp_tolerance must be > 0");
  if (options_.maxIterations < 1) throw InputError("solver.lcp_max_iterations must be >= 1");
  const int id = options_.method == LcpMethod::Lemke ? SICONOS_LCP_LEMKE : SICONOS_LCP_PGS;
  solverOptions_.reset(solver_options_create(id));
  if (!solverOptions_) throw SolverError("LCP: Siconos could not create the solver options", 0.0, 0.0);
}

LcpSolver::~LcpSolver() = default;

LcpSolution LcpSolver::solve(const MatX& M, const VecX& q) const {
  const int n = static_cast<int>(q.size());
  if (M.rows() != n || M.cols() != n) throw InputError("LcpSolver: M must be square with the size of q");
  LcpSolution out;
  out.z = VecX::Zero(n);
  out.w = q;
  if (n == 0) return out;

  // Siconos owns its copies: a dense column-major matrix (Eigen's default layout too).
  std::unique_ptr<NumericsMatrix, MatrixDeleter> nm(NM_create(NM_DENSE, n, n));
  if (!nm || !nm->matrix0) throw SolverError("LCP: Siconos could not allocate the matrix", 0.0, 0.0);
  std::memcpy(nm->matrix0, M.data(), sizeof(double) * static_cast<std::size_t>(n) * n);
  VecX qCopy = q;
  LinearComplementarityProblem problem;
  problem.size = n;
  problem.M = nm.get();
  problem.q = qCopy.data();

  SolverOptions* const so = solverOptions_.get();
  so->iparam[SICONOS_IPARAM_MAX_ITER] = options_.maxIterations;
  so->dparam[SICONOS_DPARAM_TOL] = options_.tolerance;

  // Our own check, independent of the solver: clip round-off negatives of z, recompute
  // w and measure the natural-map residual |min(z, w)|.
  auto check = [&](const VecX& zz) {
    out.z = zz.cwiseMax(0.0);
    out.w = M * out.z + q;
    double r = 0.0;
    for (int i = 0; i < n; ++i) r = std::max(r, std::abs(std::min(out.z[i], out.w[i])));
    out.residual = r / (1.0 + q.lpNorm<Eigen::Infinity>());
    // Accepted on our residual alone: a z with |min(z, Mz + q)| = 0 solves the LCP whatever
    // Siconos' code says. (lcp_pgs reports info 1 on tiny-q projection LCPs whose z is
    // exact: its own error is relative to |q| and cannot fall below its tolerance.)
    out.ok = out.residual <= options_.tolerance && out.z.allFinite() && out.w.allFinite();
  };
  VecX z = VecX::Zero(n), w = VecX::Zero(n);
  int info = -1;
  if (options_.method == LcpMethod::Lemke) {
    lcp_lexicolemke(&problem, z.data(), w.data(), &info, so);
    out.info = info;
    out.iterations = so->iparam[SICONOS_IPARAM_ITER_DONE];
    check(z);
  } else {
    // lcp_pgs stops on Siconos' own error, |z - max(0, z - w)|_2 / (1 + |q|_2), which can
    // be below the tolerance while our infinity-norm natural-map residual is above it (up
    // to a factor ~ sqrt(n)). It starts from the z it is given, so when it reports
    // convergence but our check fails, continue from its z with a 100 times tighter
    // Siconos tolerance (at most 3 times), within the same budget of sweeps.
    double tol = options_.tolerance;
    int sweeps = 0;
    for (int attempt = 0; attempt < 4; ++attempt) {
      so->dparam[SICONOS_DPARAM_TOL] = tol;
      so->iparam[SICONOS_IPARAM_MAX_ITER] = std::max(1, options_.maxIterations - sweeps);
      lcp_pgs(&problem, z.data(), w.data(), &info, so);
      sweeps += so->iparam[SICONOS_IPARAM_ITER_DONE];
      out.info = info;
      out.iterations = sweeps;
      check(z);
      if (out.ok || info != 0 || sweeps >= options_.maxIterations) break;
      tol *= 1e-2;
    }
  }
  return out;
}

}  // namespace flexmbd
