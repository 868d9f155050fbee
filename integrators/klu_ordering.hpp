/// @file
/// How the engine sets up KLU for its DAE Jacobians (used by IdaSolver, RadauSolver and
/// the micro-benchmarks, so all factor the same way).
#pragma once

#include <klu.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/dae_problem.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// The fill-reducing ordering of KLU for one DAE, chosen once at the start by factoring
/// the iteration matrix dF/dy + cj dF/dy' at the initial state with each candidate and
/// keeping the one with the fewest non-zeros in L + U (measured, not estimated: the
/// estimate of the symbolic analysis misses the fill of off-diagonal pivots):
///   - KLU's own: block-triangular form, then AMD, pivot threshold 1e-3;
///   - CAMD with the multipliers last (pivot threshold 1e-6);
///   - CAMD with the frame coordinates and the multipliers last (pivot threshold 1e-6).
/// A large flexible body fills quadratically with KLU's own, a chain of flexible links
/// quadratically with frames-and-multipliers-last (the fills of every candidate:
/// bench_spatial_scaling and bench_flexible_chain). Models without elastic coordinates (DaeProblem::eliminationGroups() without
/// a group 0) keep KLU's own without trials.
class KluOrdering {
 public:
  enum class Kind { KluDefault, MultipliersLast, FramesAndMultipliersLast };

  /// KLU's own ordering.
  KluOrdering() = default;
  /// Factors J = dF/dy + cj dF/dy' at (t0, y0, y0') with each candidate (allocates; once
  /// per integrator).
  static KluOrdering choose(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, double cj);
  /// Every candidate with its trial fill (factorNonZeros, -1 where KLU failed), in the
  /// order above; KLU's own alone (without a trial) for models without elastic
  /// coordinates. choose() keeps the sparsest; the benchmarks print them all.
  static std::vector<KluOrdering> trials(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, double cj);

  /// Sets `common`'s ordering, pivot threshold and block-triangular form. This object must
  /// outlive every klu_l_analyze with `common` (it holds the CAMD constraint set).
  void configure(klu_l_common& common) const;
  Kind kind() const { return kind_; }
  /// "klu", "camd multipliers last", "camd frames and multipliers last".
  std::string name() const;
  /// nnz(L + U) of the trial factorisation of the chosen ordering (0: no trial).
  int64_t factorNonZeros() const { return factorNonZeros_; }

 private:
  KluOrdering(Kind kind, std::vector<int64_t> constraints) : kind_(kind), constraints_(std::move(constraints)) {}
  Kind kind_ = Kind::KluDefault;
  std::vector<int64_t> constraints_;  ///< CAMD constraint set (size n), read by the ordering callback
  int64_t factorNonZeros_ = 0;
};

/// The cj of the trial factorisations: the iteration matrix at the first steps (IDA's
/// cj = 1 / h with h of 1e-6 s or less at a start), where cj dF/dy' dominates.
inline constexpr double kOrderingTrialCj = 1e6;

}  // namespace flexmbd
