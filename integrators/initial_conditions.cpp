#include "integrators/initial_conditions.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/magnitude_checks.hpp"
#include "core/number_text.hpp"
#include "core/system_evaluation.hpp"

namespace flexmbd {
namespace {

constexpr int kMaxProjectionIterations = 50;
/// Relative residual up to which dependent constraint rows count as agreeing (their
/// accelerations determined): 1e-8, far above round-off, far below a real conflict.
constexpr double kConsistentRows = 1e-8;
/// Above this size the augmented system is solved with a sparse LU.
constexpr int kDenseAugmentedLimit = 200;

/// The rows of G not released (dependent on earlier ones) as rows of the full G, ascending.
std::vector<int> dependentUnreleasedRows(const MatX& G, const std::vector<int>& released) {
  if (released.empty()) return dependentRows(G);
  std::vector<int> kept;
  for (int i = 0, k = 0; i < G.rows(); ++i) {
    if (k < static_cast<int>(released.size()) && released[k] == i) {
      ++k;
    } else {
      kept.push_back(i);
    }
  }
  std::vector<int> rows = dependentRows(withoutRows(G, released));
  for (int& r : rows) r = kept[r];
  return rows;
}

void throwIfRedundant(const System& sys, const MatX& G, const std::vector<int>& released) {
  const std::vector<int> rows = dependentUnreleasedRows(G, released);
  if (rows.empty()) return;
  std::ostringstream os;
  os << "redundant or conflicting constraints: ";
  for (size_t k = 0; k < rows.size(); ++k) os << (k ? "; " : "") << sys.describeEquation(rows[k]);
  os << (rows.size() == 1 ? " depends" : " depend")
     << " on the joints and drivers defined before (the constraint Jacobian loses rank at the given "
        "positions); remove it or free a coordinate, or start away from a singular position";
  throw ModelError(os.str());
}

/// True when global equation `row` belongs to a driver (System::describeEquation's walk).
bool isDriverEquation(const System& sys, int row) {
  for (int c = sys.numConstraints() - 1; c >= 0; --c) {
    if (row >= sys.constraintOffset(ConstraintIndex(c))) return sys.constraintIsDriver(ConstraintIndex(c));
  }
  return false;
}

/// Released equations must be redundant, not conflicting. A driver's law can disagree with
/// the equations it depends on at any later time, so a dependent driver equation is never
/// released; a dependent joint equation must agree with the kept ones at velocity and
/// acceleration level too (it holds at position level where the mechanism assembled),
/// else it fights them (a "fixed" joint on a driven angle): both are refused, named.
void throwIfReleasedConflict(const System& sys, double t0, const ConsistentState& s, const MatX& G) {
  if (s.released.empty()) return;
  const VecX rv = velocityConstraintResidual(sys, s.q, s.v, t0);                 // G v - f'
  const VecX ra = G * s.a - accelerationConstraintRhs(sys, s.q, s.v, t0);          // G a - (f'' - v^T H v)
  const double vScale = 1.0 + s.v.lpNorm<Eigen::Infinity>(), aScale = 1.0 + s.a.lpNorm<Eigen::Infinity>();
  std::ostringstream os;
  int conflicts = 0;
  for (const int r : s.released) {
    const double gScale = 1.0 + G.row(r).lpNorm<Eigen::Infinity>();
    const bool driver = isDriverEquation(sys, r);
    const bool disagrees = std::abs(rv[r]) > kConsistentRows * gScale * vScale ||
                           std::abs(ra[r]) > kConsistentRows * gScale * aScale;
    if (!driver && !disagrees) continue;
    os << (conflicts++ ? "; " : "") << sys.describeEquation(r);
    if (driver) os << " (a driver: its law may disagree with the others at later times)";
    else os << " (velocity residual " << rv[r] << ", acceleration residual " << ra[r] << ")";
  }
  if (conflicts == 0) return;
  throw ModelError("conflicting constraints: " + os.str() +
                   (conflicts == 1 ? " depends" : " depend") +
                   " on the joints and drivers defined before and cannot be released as redundant; remove it or "
                   "free a coordinate");
}

}  // namespace

namespace {

[[noreturn]] void throwSingular() {
  // The cause is named by the callers, from what they measured (computeAccelerations).
  throw ModelError("the augmented system [M G^T; G 0] is singular");
}

void split(const VecX& sol, int n, VecX& x, VecX& y) {
  if (!sol.allFinite()) throwSingular();
  x = sol.head(n);
  y = sol.tail(sol.size() - n);
}

}  // namespace

void solveAugmented(const MatX& A, int n, const VecX& r1, const VecX& r2, VecX& x, VecX& y) {
  VecX rhs(A.rows());
  rhs << r1, r2;
  const Eigen::FullPivLU<MatX> lu(A);  // rank-revealing
  if (!lu.isInvertible()) throwSingular();
  split(lu.solve(rhs), n, x, y);
}

void solveAugmented(const SpMat& A, int n, const VecX& r1, const VecX& r2, VecX& x, VecX& y) {
  if (A.rows() <= kDenseAugmentedLimit) return solveAugmented(MatX(A), n, r1, r2, x, y);
  VecX rhs(A.rows());
  rhs << r1, r2;
  Eigen::SparseLU<SpMat> lu(A);
  if (lu.info() != Eigen::Success) throwSingular();
  split(lu.solve(rhs), n, x, y);
}

void solveAugmented(const MatX& M, const MatX& G, const VecX& r1, const VecX& r2, VecX& x, VecX& y) {
  const int n = static_cast<int>(M.rows()), m = static_cast<int>(G.rows());
  if (n + m <= kDenseAugmentedLimit) {
    MatX A = MatX::Zero(n + m, n + m);
    A.topLeftCorner(n, n) = M;
    A.topRightCorner(n, m) = G.transpose();
    A.bottomLeftCorner(m, n) = G;
    return solveAugmented(A, n, r1, r2, x, y);
  }
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
  SpMat A(n + m, n + m);
  A.setFromTriplets(t.begin(), t.end());
  solveAugmented(A, n, r1, r2, x, y);
}

namespace {

/// The mass matrix's rows named by coordinate where velocities are coordinate rates.
std::vector<std::string> massRowNames(const System& sys) {
  return sys.velocitiesAreCoordinateRates() ? sys.coordinateNames() : sys.velocityNames();
}

/// What was measured of the mass matrix when the augmented system is singular: the
/// smallest and largest diagonal entries, their coordinates and ratio (a mass or inertia
/// tiny beside the others makes [M G^T; G 0] numerically singular).
std::string massDiagonalReport(const System& sys, const MatX& M) {
  if (M.rows() == 0) return "";
  const std::vector<std::string> names = massRowNames(sys);
  Eigen::Index lo = 0, hi = 0;
  const VecX d = M.diagonal().cwiseAbs();
  d.minCoeff(&lo);
  d.maxCoeff(&hi);
  std::string out = "; mass matrix diagonal from " + fmt(d[lo], 3) + " (" + names[lo] + ") to " + fmt(d[hi], 3) +
                    " (" + names[hi] + ")";
  if (d[lo] > 0.0) out += ", ratio " + fmt(d[hi] / d[lo], 3);
  // the likely cause only where the measurement points to it (core/magnitude_checks.hpp)
  if (!(d[hi] <= kMaxMagnitudeRatio * d[lo])) {
    out += " (more than " + fmt(kMaxMagnitudeRatio) + ": the smaller one is lost in round-off)";
  }
  return out;
}

/// A driver's rate above the largest value a scene may hold (1e100) is an overflow of its law.
constexpr double kMaxDriverRate = 1e100;

/// The first non-finite entry of the terms of the augmented system, named: a driver's law,
/// a force, or the mass matrix that overflowed (an overflow, not a singular position). Empty
/// if all are finite.
std::string nonFiniteTermReport(const System& sys, double t, const VecX& q, const VecX& v, const MatX& M,
                                const MatX& G, const VecX& Q, const VecX& rhs) {
  const std::string at = " at t = " + fmt(t, 6);
  // a driver's rate beyond the largest input value (1e100) squares to overflow in the
  // velocity terms of the other joints: the law is the cause, not the joint
  const VecX rates = velocityConstraintResidual(sys, q, VecX::Zero(v.size()), t);  // -f'(t)
  for (Eigen::Index r = 0; r < rates.size(); ++r) {
    if (isDriverEquation(sys, static_cast<int>(r)) && !(std::fabs(rates[r]) <= kMaxDriverRate)) {
      return sys.describeEquation(static_cast<int>(r)) + ": its law's rate is " + fmt(-rates[r], 3) + at +
             " (the driver's law overflows: check its values and times)";
    }
  }
  for (Eigen::Index r = 0; r < rhs.size(); ++r) {
    if (!std::isfinite(rhs[r])) {
      return sys.describeEquation(static_cast<int>(r)) + ": its acceleration term is " + fmt(rhs[r]) + at +
             (isDriverEquation(sys, static_cast<int>(r))
                  ? " (the driver's law or its derivatives overflow: check its values and times)"
                  : " (the velocities overflow)");
    }
  }
  const std::vector<std::string> names = massRowNames(sys);
  for (Eigen::Index k = 0; k < Q.size(); ++k) {
    if (!std::isfinite(Q[k])) {
      return "the generalized force on " + names[k] + " is " + fmt(Q[k]) + at +
             " (a force, a speed or a load of the model overflows)";
    }
  }
  for (Eigen::Index k = 0; k < M.rows(); ++k) {
    if (!M.row(k).allFinite()) return "the mass matrix row of " + names[k] + " is not finite" + at;
  }
  for (Eigen::Index r = 0; r < G.rows(); ++r) {
    if (!G.row(r).allFinite()) {
      return sys.describeEquation(static_cast<int>(r)) + ": its constraint Jacobian row is not finite" + at;
    }
  }
  return "";
}

}  // namespace

void computeAccelerations(const System& sys, double t, const VecX& q, const VecX& v, VecX& a,
                          VecX& lambda, const std::vector<int>& released) {
  const VecX Q = generalizedForces(sys, t, q, v);
  const VecX rhs = withoutRows(accelerationConstraintRhs(sys, q, v, t), released);
  VecX kept;  // the multipliers of the rows not released
  try {
    // the same component loops into a dense array for small systems, sparse triplets above
    const int n = sys.numVelocities();
    if (!released.empty()) {
      MatX G;
      evaluateConstraints(sys, q, t, nullptr, &G);
      solveAugmented(massMatrix(sys, q), withoutRows(G, released), Q, rhs, a, kept);
    } else if (n + sys.numConstraintEquations() <= kDenseAugmentedLimit) {
      solveAugmented(denseAugmentedMatrix(sys, q), n, Q, rhs, a, kept);
    } else {
      solveAugmented(augmentedMatrix(sys, q), n, Q, rhs, a, kept);
    }
  } catch (const ModelError& e) {
    // singular: the dense arrays for the diagnosis (rank of G) and the projection
    MatX Gfull;
    evaluateConstraints(sys, q, t, nullptr, &Gfull);
    const MatX G = withoutRows(Gfull, released);
    const MatX M = massMatrix(sys, q);
    const std::string overflow =
        nonFiniteTermReport(sys, t, q, v, M, Gfull, Q, accelerationConstraintRhs(sys, q, v, t));
    if (!overflow.empty()) throw ModelError("the accelerations cannot be computed: " + overflow);
    const std::vector<int> rows = dependentUnreleasedRows(Gfull, released);
    // At a singular position the accelerations are still unique (M is regular) when the
    // constraint rows agree: a = M^-1 (Q - G^T lambda) with the minimum-norm multipliers of
    // (G M^-1 G^T) lambda = G M^-1 Q - rhs (the mass-orthogonal projection of M^-1 Q).
    bool solved = false;
    if (!rows.empty()) {
      const Eigen::LDLT<MatX> Mf(M);
      if (Mf.info() == Eigen::Success) {
        const MatX MiGt = Mf.solve(G.transpose());
        const VecX MiQ = Mf.solve(Q);
        const VecX l = (G * MiGt).completeOrthogonalDecomposition().solve(G * MiQ - rhs);
        const VecX acc = MiQ - MiGt * l;
        // the rows agree when the projected accelerations satisfy them (to round-off of the terms)
        const double scale = (G * MiQ).cwiseAbs().maxCoeff() + rhs.cwiseAbs().maxCoeff() + 1.0;
        if (acc.allFinite() && l.allFinite() && (G * acc - rhs).cwiseAbs().maxCoeff() <= kConsistentRows * scale) {
          a = acc;
          kept = l;
          solved = true;
        }
      }
    }
    if (!solved) {
      std::string rank;
      for (size_t k = 0; k < rows.size(); ++k) rank += (k ? "; " : "") + sys.describeEquation(rows[k]);
      throw ModelError(e.what() + massDiagonalReport(sys, M) +
                       (rows.empty() ? std::string("; the constraint Jacobian has full rank")
                                     : "; dependent constraint rows: " + rank));
    }
  }
  if (released.empty()) {
    lambda = std::move(kept);
    return;
  }
  lambda = VecX::Zero(sys.numConstraintEquations());
  for (int i = 0, k = 0, r = 0; i < lambda.size(); ++i) {
    if (k < static_cast<int>(released.size()) && released[k] == i) {
      ++k;
    } else {
      lambda[i] = kept[r++];
    }
  }
}

ConsistentState computeConsistentState(const System& sys, double t0, const VecX& q0, const VecX& v0,
                                       const ReleasedEquations& released) {
  const int nv = sys.numVelocities(), m = sys.numConstraintEquations();
  ConsistentState s;
  s.q = q0;
  VecX g;
  MatX G;
  evaluateConstraints(sys, s.q, t0, &g, &G);
  // Redundancy is a property of the model: check it where the user put it (released
  // equations are detected where the mechanism is assembled, below).
  if (!released.detect) {
    s.released = released.rows;
    throwIfRedundant(sys, G, s.released);
  }
  // Elastic coordinates keep their given values when the frame coordinates alone can
  // satisfy the constraints (a body is not deformed, nor set vibrating, to assemble the
  // mechanism); otherwise every coordinate takes part.
  std::vector<int> cols = sys.frameVelocities();
  const auto restrictCols = [&](const MatX& A) {
    MatX B(A.rows(), cols.size());
    for (size_t k = 0; k < cols.size(); ++k) B.col(k) = A.col(cols[k]);
    return B;
  };
  // (the frame coordinates do not suffice when they lose rank the whole G does not lose)
  if (static_cast<int>(cols.size()) < nv && dependentRows(restrictCols(G)).size() > dependentRows(G).size()) {
    cols.resize(nv);
    for (int k = 0; k < nv; ++k) cols[k] = k;
  }
  // 1. Newton with minimum-norm corrections in velocity space: dv = -G^+ g, q <- q (+) dv
  //    (GolubVanLoan2013, sec. 5.5.4).
  const double scale = 1.0 + s.q.lpNorm<Eigen::Infinity>();
  const double tol = 1e-13 * scale;
  int it = 0;
  for (; it < kMaxProjectionIterations && m > 0 && g.lpNorm<Eigen::Infinity>() > tol; ++it) {
    const Eigen::CompleteOrthogonalDecomposition<MatX> cod(restrictCols(G));
    const VecX dq = -cod.solve(g);
    if (!dq.allFinite()) break;
    if (sys.velocitiesAreCoordinateRates()) {
      for (size_t k = 0; k < cols.size(); ++k) s.q[cols[k]] += dq[k];
    } else {
      VecX dv = VecX::Zero(nv);
      for (size_t k = 0; k < cols.size(); ++k) dv[cols[k]] = dq[k];
      s.q = sys.applyIncrement(s.q, dv);
    }
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
      os << (k ? ", " : "") << sys.describeEquation(rows[k]) << " = " << g[rows[k]];
    }
    throw ModelError(os.str());
  }
  // The rank may drop on the way (a singular position): check again where we arrived.
  // Released equations: those dependent at the assembled position (a structural
  // redundancy persists along the motion; docs/formulations.md).
  if (released.detect) s.released = dependentRows(G);
  throwIfRedundant(sys, G, s.released);
  const MatX Gi = withoutRows(G, s.released);  // the independent rows
  // 2. Velocities: min (v - v0)^T M (v - v0) subject to G v = f'(t0), over the same
  //    coordinates as the positions (elastic velocities kept at their given values).
  const MatX M = massMatrix(sys, s.q);
  const VecX df = withoutRows(-velocityConstraintResidual(sys, s.q, VecX::Zero(nv), t0), s.released);  // = f'(t0)
  s.v = v0;
  {
    MatX Mr(cols.size(), cols.size());
    VecX v0r(cols.size());
    for (size_t i = 0; i < cols.size(); ++i) {
      v0r[i] = v0[cols[i]];
      for (size_t j = 0; j < cols.size(); ++j) Mr(i, j) = M(cols[i], cols[j]);
    }
    VecX vr, nu;
    VecX keptVelocities = v0;  // contribution of the coordinates that stay fixed
    for (int c : cols) keptVelocities[c] = 0.0;
    try {
      solveAugmented(Mr, restrictCols(Gi), Mr * v0r, df - Gi * keptVelocities, vr, nu);
    } catch (const ModelError& e) {
      // what was measured: a non-finite velocity, driver rate or mass, else the mass spread
      std::string why;
      const std::vector<std::string> names = massRowNames(sys);
      for (Eigen::Index k = 0; k < v0.size() && why.empty(); ++k) {
        if (!std::isfinite(v0[k])) why = "; the given velocity of " + names[k] + " is " + fmt(v0[k]);
      }
      for (Eigen::Index r = 0; r < df.size() && why.empty(); ++r) {
        if (!std::isfinite(df[r])) why = "; the rate of " +
                    (s.released.empty() ? sys.describeEquation(static_cast<int>(r)) : std::string("a driver")) +
                    " is " + fmt(df[r]);
      }
      if (why.empty() && !(Mr * v0r).allFinite()) why = "; the given velocities times the masses overflow";
      throw ModelError(std::string("the initial velocities cannot be made consistent: ") + e.what() +
                       (why.empty() ? massDiagonalReport(sys, M) : why));
    }
    for (size_t k = 0; k < cols.size(); ++k) s.v[cols[k]] = vr[k];
  }
  // 3. Accelerations and multipliers: M a + G^T lambda = Q, G a = f'' - v^T H v (Haug1989).
  computeAccelerations(sys, t0, s.q, s.v, s.a, s.lambda, s.released);
  if (released.detect) throwIfReleasedConflict(sys, t0, s, G);
  return s;
}

}  // namespace flexmbd
