#include "integrators/initial_conditions.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <algorithm>
#include <sstream>

#include "core/errors.hpp"
#include "core/system_evaluation.hpp"

namespace flexmbd {
namespace {

constexpr int kMaxProjectionIterations = 50;
/// Above this size the augmented system is solved with a sparse LU.
constexpr int kDenseAugmentedLimit = 200;

/// Names the constraint (joint or driver) that owns global equation `row`.
std::string constraintOfRow(const System& sys, int row) {
  for (int c = sys.numConstraints() - 1; c >= 0; --c) {
    const ConstraintIndex ci(c);
    if (row >= sys.constraintOffset(ci)) {
      const Constraint& con = sys.constraint(ci);
      return std::string(con.isDriver() ? "driver '" : "joint '") + con.name() + "' (" +
             con.typeName() + ", equation " + std::to_string(row - sys.constraintOffset(ci)) + ")";
    }
  }
  return "?";
}

void throwIfRedundant(const System& sys, const MatX& G) {
  const std::vector<int> rows = dependentConstraintRows(G);
  if (rows.empty()) return;
  std::ostringstream os;
  os << "redundant or conflicting constraints: ";
  for (size_t k = 0; k < rows.size(); ++k) os << (k ? "; " : "") << constraintOfRow(sys, rows[k]);
  os << (rows.size() == 1 ? " depends" : " depend")
     << " on the joints and drivers defined before (the constraint Jacobian loses rank); remove "
        "it or free a coordinate";
  throw ModelError(os.str());
}

}  // namespace

std::vector<int> dependentConstraintRows(const MatX& G, double rankTolerance) {
  // Modified Gram-Schmidt on the rows, in order: a row whose component orthogonal to
  // the earlier rows is below rankTolerance times its own norm is dependent.
  std::vector<int> dependent;
  std::vector<VecX> basis;
  for (int i = 0; i < G.rows(); ++i) {
    VecX r = G.row(i).transpose();
    const double norm0 = r.norm();
    for (const VecX& b : basis) r -= b.dot(r) * b;
    const double rn = r.norm();
    if (norm0 == 0.0 || rn <= rankTolerance * norm0) {
      dependent.push_back(i);
    } else {
      basis.push_back(r / rn);
    }
  }
  return dependent;
}

void solveAugmented(const MatX& M, const MatX& G, const VecX& r1, const VecX& r2, VecX& x, VecX& y) {
  const int n = static_cast<int>(M.rows()), m = static_cast<int>(G.rows());
  VecX rhs(n + m), sol;
  rhs << r1, r2;
  const char* singular =
      "the augmented system [M G^T; G 0] is singular: constraints are redundant or a body has no mass";
  if (n + m <= kDenseAugmentedLimit) {
    MatX A = MatX::Zero(n + m, n + m);
    A.topLeftCorner(n, n) = M;
    A.topRightCorner(n, m) = G.transpose();
    A.bottomLeftCorner(m, n) = G;
    const Eigen::FullPivLU<MatX> lu(A);
    if (!lu.isInvertible()) throw ModelError(singular);
    sol = lu.solve(rhs);
  } else {
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        if (M(i, j) != 0.0) t.emplace_back(i, j, M(i, j));
      }
      for (int i = 0; i < m; ++i) {
        if (G(i, j) != 0.0) {
          t.emplace_back(n + i, j, G(i, j));
          t.emplace_back(j, n + i, G(i, j));
        }
      }
    }
    Eigen::SparseMatrix<double> A(n + m, n + m);
    A.setFromTriplets(t.begin(), t.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(A);
    if (lu.info() != Eigen::Success) throw ModelError(singular);
    sol = lu.solve(rhs);
  }
  if (!sol.allFinite()) throw ModelError(singular);
  x = sol.head(n);
  y = sol.tail(m);
}

void computeAccelerations(const System& sys, double t, const VecX& q, const VecX& v, VecX& a,
                          VecX& lambda) {
  MatX G;
  evaluateConstraints(sys, q, t, nullptr, &G);
  solveAugmented(massMatrix(sys, q), G, generalizedForces(sys, t, q, v),
                 accelerationConstraintRhs(sys, q, v, t), a, lambda);
}

ConsistentState computeConsistentState(const System& sys, double t0, const VecX& q0, const VecX& v0) {
  const int nq = sys.numCoordinates(), m = sys.numConstraintEquations();
  ConsistentState s;
  s.q = q0;
  VecX g;
  MatX G;
  evaluateConstraints(sys, s.q, t0, &g, &G);
  // Redundancy is a property of the model: check it where the user put it.
  throwIfRedundant(sys, G);
  // 1. Newton with minimum-norm corrections: dq = -G^+ g.
  const double scale = 1.0 + s.q.lpNorm<Eigen::Infinity>();
  const double tol = 1e-13 * scale;
  int it = 0;
  for (; it < kMaxProjectionIterations && m > 0 && g.lpNorm<Eigen::Infinity>() > tol; ++it) {
    const Eigen::CompleteOrthogonalDecomposition<MatX> cod(G);
    const VecX dq = -cod.solve(g);
    if (!dq.allFinite()) break;
    s.q += dq;
    evaluateConstraints(sys, s.q, t0, &g, &G);
  }
  s.positionIterations = it;
  s.positionResidual = m > 0 ? g.lpNorm<Eigen::Infinity>() : 0.0;
  if (!(s.positionResidual <= 1e-10 * scale)) {
    // name the constraints carrying the residual, largest first
    std::vector<int> rows(m);
    for (int i = 0; i < m; ++i) rows[i] = i;
    std::sort(rows.begin(), rows.end(), [&](int a, int b) { return std::abs(g[a]) > std::abs(g[b]); });
    std::ostringstream os;
    os << "the mechanism cannot be assembled from the given positions: residual " << s.positionResidual
       << " after " << it << " Newton iterations; largest violations: ";
    for (int k = 0; k < std::min(m, 3); ++k) {
      if (!(std::abs(g[rows[k]]) > tol) && k > 0) break;
      os << (k ? ", " : "") << constraintOfRow(sys, rows[k]) << " = " << g[rows[k]];
    }
    throw ModelError(os.str());
  }
  // The rank may drop on the way (a singular position): check again where we arrived.
  throwIfRedundant(sys, G);
  // 2. Velocities: min (v - v0)^T M (v - v0) subject to G v = f'(t0).
  const MatX M = massMatrix(sys, s.q);
  const VecX df = -velocityConstraintResidual(sys, s.q, VecX::Zero(nq), t0);  // = f'(t0)
  VecX nu;
  solveAugmented(M, G, M * v0, df, s.v, nu);
  // 3. Accelerations and multipliers: M a + G^T lambda = Q, G a = f'' - v^T H v.
  computeAccelerations(sys, t0, s.q, s.v, s.a, s.lambda);
  return s;
}

}  // namespace flexmbd
