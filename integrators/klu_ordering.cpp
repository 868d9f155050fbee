#include "integrators/klu_ordering.hpp"

#include <camd.h>

#include <algorithm>
#include <array>

#include "core/sparse_pattern.hpp"

namespace flexmbd {
namespace {

/// KLU ordering callback: constrained AMD on A + A^T with the constraint set in
/// common->user_data (group 0 eliminated first).
int64_t camdOrdering(int64_t n, int64_t* Ap, int64_t* Ai, int64_t* perm, klu_l_common* common) {
  const auto* groups = static_cast<const std::vector<int64_t>*>(common->user_data);
  double control[CAMD_CONTROL], info[CAMD_INFO];
  camd_l_defaults(control);
  if (camd_l_order(n, Ap, Ai, perm, control, info, const_cast<int64_t*>(groups->data())) < CAMD_OK) return 0;
  return std::max<int64_t>(1, static_cast<int64_t>(info[CAMD_LNZ]));
}

/// With the CAMD orders, KLU must keep to the fill-reducing order: the elastic 2 x 2
/// blocks [cj, -1; K, cj M] have positive Schur complements cj M + K / cj, so their
/// diagonal pivots are safe; a threshold of 1e-6 still rejects the (near-)zero diagonals
/// of the multipliers (a threshold of 1e-12 let the rigid slider-crank tests fail to
/// converge).
constexpr double kCamdPivotTolerance = 1e-6;

/// The CAMD constraint set of an ordering from DaeProblem::eliminationGroups() (0 elastic,
/// 1 frame, 2 multiplier).
std::vector<int64_t> constraintsFor(KluOrdering::Kind kind, const std::vector<int64_t>& groups) {
  std::vector<int64_t> c(groups.size());
  for (size_t k = 0; k < groups.size(); ++k) {
    c[k] = kind == KluOrdering::Kind::MultipliersLast ? (groups[k] == 2 ? 1 : 0) : (groups[k] == 0 ? 0 : 1);
  }
  return c;
}

/// nnz(L + U) of J factored with `ordering`, or -1 if KLU fails.
int64_t trialFill(const KluOrdering& ordering, int64_t n, std::vector<int64_t>& Ap, std::vector<int64_t>& Ai,
                  std::vector<double>& values) {
  klu_l_common common;
  klu_l_defaults(&common);
  ordering.configure(common);
  klu_l_symbolic* symbolic = klu_l_analyze(n, Ap.data(), Ai.data(), &common);
  if (!symbolic) return -1;
  klu_l_numeric* numeric = klu_l_factor(Ap.data(), Ai.data(), values.data(), symbolic, &common);
  const int64_t fill = numeric ? numeric->lnz + numeric->unz : -1;
  if (numeric) klu_l_free_numeric(&numeric, &common);
  klu_l_free_symbolic(&symbolic, &common);
  return fill;
}

}  // namespace

std::vector<KluOrdering> KluOrdering::trials(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0,
                                             double cj) {
  const std::vector<int64_t> groups = dae.eliminationGroups();
  if (std::find(groups.begin(), groups.end(), 0) == groups.end()) return {KluOrdering()};
  const SparsePattern& p = dae.pattern();
  std::vector<int64_t> Ap(p.colStart().begin(), p.colStart().end()), Ai(p.rowIndex().begin(), p.rowIndex().end());
  std::vector<double> values(Ai.size(), 0.0);
  JacobianSink sink = JacobianSink::sparse(values.data(), p);
  dae.jacobian(t0, y0.data(), yp0.data(), cj, sink);
  std::vector<KluOrdering> out;
  out.push_back(KluOrdering());
  for (Kind kind : {Kind::MultipliersLast, Kind::FramesAndMultipliersLast}) {
    out.push_back(KluOrdering(kind, constraintsFor(kind, groups)));
  }
  for (KluOrdering& o : out) o.factorNonZeros_ = trialFill(o, p.size(), Ap, Ai, values);
  return out;
}

KluOrdering KluOrdering::choose(const DaeProblem& dae, double t0, const VecX& y0, const VecX& yp0, double cj) {
  std::vector<KluOrdering> all = trials(dae, t0, y0, yp0, cj);
  size_t best = 0;
  for (size_t k = 1; k < all.size(); ++k) {
    const int64_t fill = all[k].factorNonZeros_, bestFill = all[best].factorNonZeros_;
    if (fill >= 0 && (bestFill < 0 || fill < bestFill)) best = k;
  }
  return std::move(all[best]);
}

void KluOrdering::configure(klu_l_common& common) const {
  if (kind_ == Kind::KluDefault) return;
  common.btf = 0;  // one block: the constraint set indexes the whole matrix
  common.ordering = 3;
  common.user_order = &camdOrdering;
  common.user_data = const_cast<std::vector<int64_t>*>(&constraints_);
  common.tol = kCamdPivotTolerance;
}

std::string KluOrdering::name() const {
  switch (kind_) {
    case Kind::KluDefault: return "klu";
    case Kind::MultipliersLast: return "camd multipliers last";
    case Kind::FramesAndMultipliersLast: return "camd frames and multipliers last";
  }
  return "?";
}

}  // namespace flexmbd
