/// @file
/// Linear complementarity problems  w = M z + q,  z >= 0,  w >= 0,  z^T w = 0 (Doc001, method 1),
/// solved with Siconos numerics (lexicographic Lemke or projected Gauss-Seidel) behind a
/// small interface, so the time-stepper does not see Siconos.
#pragma once

#include <memory>
#include <string>

#include "core/types.hpp"

struct SolverOptions;  // Siconos numerics (SolverOptions.h), kept out of this header

namespace flexmbd {

enum class LcpMethod {
  Lemke,                 ///< Siconos lcp_lexicolemke: pivoting, exact up to round-off
  ProjectedGaussSeidel,  ///< Siconos lcp_pgs: iterative, needs a positive diagonal
};
std::string toString(LcpMethod m);
/// "lemke" or "pgs". @throws InputError otherwise.
LcpMethod parseLcpMethod(const std::string& name);

struct LcpOptions {
  LcpMethod method = LcpMethod::Lemke;
  /// Acceptance: the relative residual (see LcpSolution::residual) must not exceed it.
  /// Also the stopping tolerance handed to PGS.
  double tolerance = 1e-10;
  int maxIterations = 100000;  ///< PGS sweeps, Lemke pivots
};

struct LcpSolution {
  VecX z, w;           ///< w = M z + q recomputed from z
  /// max_i |min(z_i, w_i)| / (1 + |q|_inf): zero at an exact solution.
  double residual = 0.0;
  int iterations = 0;  ///< pivots (Lemke) or sweeps (PGS) reported by Siconos
  int info = 0;        ///< Siconos' return code (0: converged)
  bool ok = true;      ///< residual <= tolerance (Siconos' info is reported, not used)
};

/// Holds one Siconos SolverOptions for all its solves (created in the constructor, freed
/// in the destructor): creating them per solve cost an allocation per step, and Siconos'
/// solver_options_delete frees only their contents, not the structure itself.
/// Not copyable; solve() is not reentrant (one solver per thread).
class LcpSolver {
 public:
  /// @throws InputError if tolerance <= 0 or maxIterations < 1.
  explicit LcpSolver(const LcpOptions& options);
  ~LcpSolver();
  LcpSolver(const LcpSolver&) = delete;
  LcpSolver& operator=(const LcpSolver&) = delete;
  /// @pre M square, q of the same size. Never throws on non-convergence: check ok.
  /// An empty problem returns an empty solution with ok = true.
  LcpSolution solve(const MatX& M, const VecX& q) const;
  const LcpOptions& options() const { return options_; }

 private:
  struct OptionsDeleter {
    void operator()(SolverOptions* o) const;
  };
  LcpOptions options_;
  std::unique_ptr<SolverOptions, OptionsDeleter> solverOptions_;
};

}  // namespace flexmbd
