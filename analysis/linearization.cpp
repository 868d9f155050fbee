#include "analysis/linearization.hpp"

#include <tuple>

#include <Eigen/Dense>
#include <Eigen/SparseLU>
// GCC 12 warns -Wuse-after-free inside Spectra's UpperHessenbergEigen (Eigen temporaries
// freed and reallocated by resize): a false positive of its inlining analysis.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <Spectra/GenEigsRealShiftSolver.h>

#include <algorithm>
#include <cmath>

#include "core/dae_system.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/number_text.hpp"
#include "core/system_evaluation.hpp"
#include "core/number_text.hpp"
#include "integrators/initial_conditions.hpp"
#include "analysis/static_equilibrium.hpp"

namespace flexmbd {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

SpMat fromTriplets(int rows, int cols, const Triplets& t) {
  SpMat S(rows, cols);
  S.setFromTriplets(t.begin(), t.end());  // duplicates summed
  return S;
}

/// The entries of `all` in rows [r0, r0 + rows) and columns [c0, c0 + cols), shifted to (0, 0).
Triplets blockOf(const Triplets& all, int r0, int rows, int c0, int cols, double scale = 1.0) {
  Triplets out;
  for (const auto& e : all) {
    const int r = e.row() - r0, c = e.col() - c0;
    if (r >= 0 && r < rows && c >= 0 && c < cols) out.emplace_back(r, c, scale * e.value());
  }
  return out;
}

/// T(q) (nq x nv) or T+(q) (nv x nq), body by body (Body::coordinateRateMatrix / Inverse).
SpMat rateMatrix(const System& sys, const VecX& q, bool inverse) {
  Triplets t;
  MatX Tb;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int nqb = body.numCoordinates();
    if (nqb == 0) continue;
    const int qoff = sys.coordinateOffset(bi), voff = sys.velocityOffset(bi);
    if (body.velocitiesAreCoordinateRates()) {
      for (int k = 0; k < nqb; ++k) t.emplace_back(inverse ? voff + k : qoff + k, inverse ? qoff + k : voff + k, 1.0);
      continue;
    }
    const auto qb = q.segment(qoff, nqb);
    if (inverse) {
      body.coordinateRateInverse(qb, Tb);
    } else {
      body.coordinateRateMatrix(qb, Tb);
    }
    const int r0 = inverse ? voff : qoff, c0 = inverse ? qoff : voff;
    for (int j = 0; j < Tb.cols(); ++j) {
      for (int i = 0; i < Tb.rows(); ++i) {
        if (Tb(i, j) != 0.0) t.emplace_back(r0 + i, c0 + j, Tb(i, j));
      }
    }
  }
  return inverse ? fromTriplets(sys.numVelocities(), sys.numCoordinates(), t)
                 : fromTriplets(sys.numCoordinates(), sys.numVelocities(), t);
}

/// B = T+ (d(T v)/dq T - [d(T e_j)/dq T v]_j) (nv x nv): dx' = dv + B dx for the increment
/// dx of q = q_ref(t) (+) dx carried along the reference motion (derivation: docs/modes.md,
/// "Kinematic term"). Only bodies with T != I contribute, and of them only the frame
/// velocities (elastic velocities are their coordinates' rates: d(T e_j)/dq = 0).
SpMat kinematicTerm(const System& sys, const VecX& q, const VecX& v, const SpMat& T, const SpMat& Tinv) {
  const int nq = sys.numCoordinates(), nv = sys.numVelocities();
  Triplets dTv, bracket;  // d(T v)/dq (nq x nq) and [d(T e_j)/dq T v]_j (nq x nv)
  JacobianSink dTvSink = JacobianSink::recorder(&dTv);
  const VecX Tv = T * v;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int nqb = body.numCoordinates(), nvb = body.numVelocities();
    if (nqb == 0 || body.velocitiesAreCoordinateRates()) continue;
    const int qoff = sys.coordinateOffset(bi), voff = sys.velocityOffset(bi);
    const auto qb = q.segment(qoff, nqb);
    body.addCoordinateRateJacobian(qb, v.segment(voff, nvb), MatrixSink(dTvSink, qoff, qoff));
    VecX ej = VecX::Zero(nvb);
    for (int j = 0; j < body.numFrameVelocities(); ++j) {
      ej.setZero();
      ej[j] = 1.0;
      MatX dTe = MatX::Zero(nqb, nqb);
      body.addCoordinateRateJacobian(qb, ej, dTe);
      const VecX col = dTe * Tv.segment(qoff, nqb);
      for (int i = 0; i < nqb; ++i) {
        if (col[i] != 0.0) bracket.emplace_back(qoff + i, voff + j, col[i]);
      }
    }
  }
  if (dTv.empty() && bracket.empty()) return SpMat(nv, nv);
  const SpMat inner = fromTriplets(nq, nq, dTv) * T - fromTriplets(nq, nv, bracket);
  SpMat B = Tinv * inner;
  B.prune(0.0);
  return B;
}

/// G' = dG/dq [T v] (m x nv, dense): the rate of the constraint Jacobian along the
/// motion with velocities v, from the analytic curvature H_a = d(G_a^T)/dq of every
/// constraint: G'_a^T = H_a (T v).
MatX constraintJacobianRate(const System& sys, const VecX& q, const VecX& v) {
  MatX out = MatX::Zero(sys.numConstraintEquations(), sys.numVelocities());
  const VecX Tv = sys.coordinateRates(q, v);
  ConstraintEvaluation ev;
  VecX w;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    con.evaluate(sys.constraintStates(ci, q.data()), true, ev);
    gather(sys.constraintCoordinateColumns(ci), Tv.data(), w);
    const auto& cols = sys.constraintColumns(ci);
    const int row = sys.constraintOffset(ci);
    for (int a = 0; a < con.numEquations(); ++a) {
      const VecX col = ev.H[a] * w;
      for (size_t k = 0; k < cols.size(); ++k) out(row + a, cols[k]) += col[static_cast<Eigen::Index>(k)];
    }
  }
  return out;
}

/// Step of the central difference of G' along the motion, as the angle or length the
/// fastest velocity covers in it (truncation ~1e-8, rounding ~1e-12 relative).
constexpr double kRateDifferenceStep = 1e-4;

void checkState(const System& sys, const ReferenceState& s) {
  if (!sys.isFinalized()) throw InputError("linearize: the system must be finalized first");
  const auto bad = [](const VecX& x, int n) { return x.size() != n || !x.allFinite(); };
  if (bad(s.q, sys.numCoordinates()) || bad(s.v, sys.numVelocities()) || bad(s.a, sys.numVelocities()) ||
      bad(s.lambda, sys.numConstraintEquations())) {
    throw InputError("linearize: the reference state needs finite q (" + std::to_string(sys.numCoordinates()) +
                     "), v and a (" + std::to_string(sys.numVelocities()) + ") and lambda (" +
                     std::to_string(sys.numConstraintEquations()) + ")");
  }
}

/// Numerical rank tolerance of G, relative to its largest singular value / pivot.
constexpr double kRankTolerance = 1e-10;
/// Weight of elastic velocities when choosing the dependent coordinates of coordinate
/// partitioning: frame velocities are taken as dependent first (pivoted QR of G W).
constexpr double kElasticPivotWeight = 1e-3;

SpMat svdBasis(const MatX& G, int& rank) {
  const int nv = static_cast<int>(G.cols());
  if (G.rows() == 0) {
    rank = 0;
    SpMat I(nv, nv);
    I.setIdentity();
    return I;
  }
  Eigen::BDCSVD<MatX> svd(G, Eigen::ComputeFullV);
  const VecX& s = svd.singularValues();
  rank = 0;
  for (Eigen::Index k = 0; k < s.size(); ++k) rank += s[k] > kRankTolerance * std::max(s[0], 1e-300) ? 1 : 0;
  const MatX N = svd.matrixV().rightCols(nv - rank);
  return N.sparseView();
}

SpMat partitioningBasis(const MatX& G, const std::vector<CoordinateKind>& kinds, int& rank, std::vector<int>& dep) {
  const int nv = static_cast<int>(G.cols());
  MatX GW = G;
  for (int k = 0; k < nv; ++k) {
    if (kinds[k] == CoordinateKind::Elastic) GW.col(k) *= kElasticPivotWeight;
  }
  Eigen::ColPivHouseholderQR<MatX> qr(GW);
  qr.setThreshold(kRankTolerance);
  rank = G.rows() == 0 ? 0 : static_cast<int>(qr.rank());
  const auto& perm = qr.colsPermutation().indices();
  dep.assign(perm.data(), perm.data() + rank);
  std::vector<int> indep(perm.data() + rank, perm.data() + nv);
  std::sort(dep.begin(), dep.end());
  std::sort(indep.begin(), indep.end());
  MatX Gd(G.rows(), rank), Gi(G.rows(), nv - rank);
  for (int k = 0; k < rank; ++k) Gd.col(k) = G.col(dep[k]);
  for (int k = 0; k < nv - rank; ++k) Gi.col(k) = G.col(indep[k]);
  // G_d dx_d + G_i x = 0: dx_d = -G_d^+ G_i x (G_d has full column rank; redundant rows agree)
  const MatX X = rank > 0 ? MatX(-Gd.colPivHouseholderQr().solve(Gi)) : MatX(0, nv - rank);
  Triplets t;
  for (int k = 0; k < nv - rank; ++k) t.emplace_back(indep[k], k, 1.0);
  for (int k = 0; k < nv - rank; ++k) {
    for (int i = 0; i < rank; ++i) {
      if (std::abs(X(i, k)) > 1e-14) t.emplace_back(dep[i], k, X(i, k));
    }
  }
  return fromTriplets(nv, nv - rank, t);
}

/// Mode from an eigenvalue and the displacement part x of its eigenvector: shape N x
/// scaled so that its largest entry is 1.
Mode makeMode(std::complex<double> s, const Eigen::VectorXcd& x, const SpMat& N) {
  Mode m;
  m.eigenvalue = s;
  m.omega = std::abs(s);
  m.frequencyHz = m.omega / (2.0 * M_PI);
  m.dampingRatio = m.omega > 0.0 ? -s.real() / m.omega : 0.0;
  m.shape = N.cast<std::complex<double>>() * x;
  Eigen::Index k = 0;
  if (m.shape.size() > 0 && m.shape.cwiseAbs().maxCoeff(&k) > 0.0) m.shape /= m.shape[k];
  return m;
}

/// Sorted selection: Im s >= 0 (one of each complex pair, every real eigenvalue), the
/// zero eigenvalues (|s| <= zeroTol, two per rigid-body degree of freedom) halved, by
/// increasing |s| then Im s; at most `count`.
std::vector<Mode> selectModes(std::vector<Mode> all, int count, double zeroTol) {
  std::vector<Mode> zeros, others;
  for (auto& m : all) {
    if (m.omega <= zeroTol) {
      m.eigenvalue = 0.0;
      m.omega = m.frequencyHz = m.dampingRatio = 0.0;
      zeros.push_back(std::move(m));
    } else if (m.eigenvalue.imag() >= -1e-12 * m.omega) {
      others.push_back(std::move(m));
    }
  }
  zeros.resize((zeros.size() + 1) / 2);
  std::sort(others.begin(), others.end(), [](const Mode& a, const Mode& b) {
    if (a.omega != b.omega) return a.omega < b.omega;
    return a.eigenvalue.imag() < b.eigenvalue.imag();
  });
  zeros.insert(zeros.end(), others.begin(), others.end());
  if (static_cast<int>(zeros.size()) > count) zeros.resize(count);
  return zeros;
}

/// Zero eigenvalues: |s| below this fraction of the largest |s| found (the rigid-body
/// eigenvalues of a Jordan pair come out of a dense solver near sqrt(eps) |s|_max).
constexpr double kZeroEigenvalueFraction = 1e-6;

double norm1(const SpMat& S) {
  double best = 0.0;
  for (int j = 0; j < S.outerSize(); ++j) {
    double c = 0.0;
    for (SpMat::InnerIterator it(S, j); it; ++it) c += std::abs(it.value());
    best = std::max(best, c);
  }
  return best;
}

/// max(sqrt(|Kr| / |Mr|), |Cr| / |Mr|) (1-norms), or 1 if zero: the scale of the
/// first-order form.
double frequencyScale(const ReducedSystem& red) {
  const double m = norm1(red.M);
  const double w = std::max(std::sqrt(norm1(red.K) / m), norm1(red.C) / m);
  return w > 0.0 && std::isfinite(w) ? w : 1.0;
}

/// Widest ratio of the damping's rate |Cr| / |Mr| to the stiffness' sqrt(|Kr| / |Mr|). An
/// overdamped mode has eigenvalues ~ -k/c and ~ -c/m, a ratio (w / (c/m))^2 apart: beyond
/// 1e3 the slow one falls below kZeroEigenvalueFraction (1e-6) of the fast and would be
/// reported as a rigid-body (zero) mode.
constexpr double kMaxDampingRatioOfScales = 1e3;

/// @throws SolverError when damping dominates the stiffness beyond what the eigensolvers
/// resolve (a section "damping" beta of 1e6 s: modes reported as 0 Hz otherwise).
void checkDampingScale(const ReducedSystem& red) {
  const double m = norm1(red.M);
  const double damping = norm1(red.C) / m, stiffness = std::sqrt(norm1(red.K) / m);
  if (damping > kMaxDampingRatioOfScales * stiffness && stiffness > 0.0) {
    throw SolverError("modes: the damping dominates the stiffness by " + fmt(damping / stiffness) +
                      " (|C| / |M| = " + fmt(damping) + " 1/s against sqrt(|K| / |M|) = " + fmt(stiffness) +
                      " rad/s; at most " + fmt(kMaxDampingRatioOfScales) +
                      "): the slow overdamped eigenvalues are below the solvers' resolution and would show as "
                      "rigid-body modes; lower the damping (a section's \"damping\" beta gives the damping ratio "
                      "beta omega / 2), or compute the modes without it");
  }
}

std::vector<Mode> denseModes(const ReducedSystem& red, int count) {
  const int n = static_cast<int>(red.M.rows());
  const MatX M = red.M, C = red.C, K = red.K;
  Eigen::LLT<MatX> llt(M);
  if (llt.info() != Eigen::Success) throw ModelError("modes: the reduced mass matrix is not positive definite");
  // first-order form z = [x; x' / w], z' = A z (a linearisation, TisseurMeerbergen2001), scaled
  // by a frequency w of the model's top range so that both block rows have norms ~ w: unscaled, |M^-1 K| ~ w_max^2
  // against 1 costs the low eigenvalues digits (eps w_max^2 instead of eps w_max)
  const double w = frequencyScale(red);
  MatX A = MatX::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.topRightCorner(n, n) *= w;
  A.bottomLeftCorner(n, n) = -llt.solve(K) / w;
  A.bottomRightCorner(n, n) = -llt.solve(C);
  Eigen::EigenSolver<MatX> es(A, true);
  if (es.info() != Eigen::Success) {
    throw SolverError("modes: the dense eigensolver (Eigen, QR of the " + std::to_string(2 * n) + " x " +
                      std::to_string(2 * n) + " first-order matrix) did not converge");
  }
  std::vector<Mode> all;
  double largest = 0.0;
  for (int k = 0; k < 2 * n; ++k) {
    all.push_back(makeMode(es.eigenvalues()[k], es.eigenvectors().col(k).head(n), red.N));
    largest = std::max(largest, std::abs(es.eigenvalues()[k]));
  }
  return selectModes(std::move(all), count, kZeroEigenvalueFraction * largest);
}

/// Spectra operator of the shift-invert of the pencil (A, E), A = [0 I; -K -C], E = [I 0; 0 M]
/// (the linearisation of the quadratic eigenvalue problem, TisseurMeerbergen2001):
/// y = (A - sigma E)^-1 E x, whose largest eigenvalues 1 / (s - sigma) are the s nearest sigma.
class ShiftInvertPencil {
 public:
  using Scalar = double;
  ShiftInvertPencil(const SpMat& M, const SpMat& C, const SpMat& K) : n_(static_cast<int>(M.rows())) {
    Triplets a, e;
    for (int k = 0; k < n_; ++k) {
      a.emplace_back(k, n_ + k, 1.0);
      e.emplace_back(k, k, 1.0);
    }
    const auto put = [](Triplets& t, const SpMat& S, int r0, int c0, double s) {
      for (int j = 0; j < S.outerSize(); ++j) {
        for (SpMat::InnerIterator it(S, j); it; ++it) t.emplace_back(r0 + it.row(), c0 + j, s * it.value());
      }
    };
    put(a, K, n_, 0, -1.0);
    put(a, C, n_, n_, -1.0);
    put(e, M, n_, n_, 1.0);
    A_ = fromTriplets(2 * n_, 2 * n_, a);
    E_ = fromTriplets(2 * n_, 2 * n_, e);
  }
  Eigen::Index rows() const { return 2 * n_; }
  Eigen::Index cols() const { return 2 * n_; }
  void set_shift(double sigma) {
    const SpMat S = A_ - sigma * E_;
    lu_.compute(S);
    if (lu_.info() != Eigen::Success) {
      throw SolverError("modes: the sparse eigensolver (Spectra, shift-invert about " + fmt(sigma, 6) +
                        "): the shifted pencil is singular, an eigenvalue lies at the shift; the dense solver finds it "
                        "(--solver dense, EigenSolverKind::Dense)");
    }
  }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<const VecX> xv(x, 2 * n_);
    Eigen::Map<VecX>(y, 2 * n_) = lu_.solve(E_ * xv);
  }

 private:
  int n_;
  SpMat A_, E_;
  mutable Eigen::SparseLU<SpMat> lu_;  // solve() is const in Eigen; factorised in set_shift
};

/// Restarts of the sparse eigensolver before it gives up (converged cases take 1 to 3).
constexpr int kMaxRestarts = 1000;

/// Dimension of the Arnoldi basis for `nev` eigenvalues of an operator of order `order`:
/// 2 nev + 2, at least 20, at most the order. Even: Spectra advises 2 nev + 1, but a real
/// Hessenberg matrix of odd order has a real Ritz value, which approximates none of the
/// conjugate pairs of an oscillator's spectrum. Measured (examples/, 1 to 20 modes): 21
/// vectors for 4 modes of spatial_slider_crank_elastic.json did not converge in 1000
/// restarts, 22 did in 2; every even basis converged within 3 restarts, odd ones in up to 101.
int arnoldiBasisSize(int nev, int order) { return std::min(order, std::max(2 * nev + 2, 20)); }

std::vector<Mode> sparseModes(const ReducedSystem& red, int count, double shift) {
  const int n = static_cast<int>(red.M.rows());
  ShiftInvertPencil op(red.M, red.C, red.K);
  // two eigenvalues per mode (a conjugate pair), two spare
  const int nev = std::min(2 * count + 2, 2 * n - 3);
  const int ncv = arnoldiBasisSize(nev, 2 * n);
  Spectra::GenEigsRealShiftSolver<ShiftInvertPencil> eigs(op, nev, ncv, shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, kMaxRestarts, 1e-10);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw SolverError("modes: the sparse eigensolver (Spectra, shift-invert about " + fmt(shift, 6) +
                      ") did not converge: " + std::to_string(eigs.eigenvalues().size()) + " of the " +
                      std::to_string(nev) + " eigenvalues nearest the shift in " + std::to_string(kMaxRestarts) +
                      " restarts, Krylov subspace of " + std::to_string(ncv) +
                      " vectors; the dense solver finds them (--solver dense, EigenSolverKind::Dense)");
  }
  const Eigen::VectorXcd s = eigs.eigenvalues();
  const Eigen::MatrixXcd Z = eigs.eigenvectors();
  std::vector<Mode> all;
  double largest = 0.0;
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    all.push_back(makeMode(s[k], Z.col(k).head(n), red.N));
    largest = std::max(largest, std::abs(s[k]));
  }
  return selectModes(std::move(all), count, kZeroEigenvalueFraction * largest);
}

/// A state at rest is taken as an equilibrium when no acceleration exceeds this (SI units:
/// 1e-9 of the acceleration of gravity, rounding of the augmented solve).
constexpr double kEquilibriumAcceleration = 1e-8;

}  // namespace

ReferenceState referenceStateAt(const System& sys, double t0, const VecX& q0, const VecX& v0,
                                const ReleasedEquations& released) {
  const ConsistentState c = computeConsistentState(sys, t0, q0, v0, released);
  ReferenceState s;
  s.t = t0;
  s.q = c.q;
  s.v = c.v;
  computeAccelerations(sys, t0, s.q, s.v, s.a, s.lambda, c.released);
  // at rest but accelerating: not an equilibrium yet, solve for it (a free body at rest
  // without load is one already, and its static tangent would be singular)
  if (c.v.lpNorm<Eigen::Infinity>() == 0.0 && s.a.lpNorm<Eigen::Infinity>() > kEquilibriumAcceleration) {
    StaticEquilibriumOptions options;
    options.released = c.released;
    const StaticEquilibrium eq = solveStaticEquilibrium(sys, t0, c.q, options);
    s.q = eq.q;
    s.lambda = eq.lambda;
    s.a = VecX::Zero(sys.numVelocities());
  }
  return s;
}

ReferenceState solveSteadyMotion(const System& sys, double t0, const VecX& q0, const VecX& v0) {
  // Newton iteration limit and tolerance on max |dx| relative to 1 + max |q| (as the static solve)
  constexpr int kMaxIterations = 50;
  constexpr double kTolerance = 1e-10;
  const ConsistentState c = computeConsistentState(sys, t0, q0, v0);
  const DaeSystem dae(sys, Formulation::Index3);
  const DaeLayout& L = dae.layout();
  const int nv = L.nv, m = L.m;
  VecX q = c.q, lambda = VecX::Zero(m), y, yp, F(L.size);
  const VecX zero = VecX::Zero(nv);
  double step = 0.0;
  for (int it = 0; it < kMaxIterations; ++it) {
    dae.packState(q, c.v, zero, lambda, y, yp);
    dae.residual(t0, y.data(), yp.data(), F.data());
    Triplets J;
    JacobianSink sink = JacobianSink::recorder(&J);
    dae.jacobian(t0, y.data(), yp.data(), 0.0, sink);
    const SpMat T = rateMatrix(sys, q, false);
    // [Kq T, G^T; Gq T, 0]: the F_v and F_g rows of the index-3 Jacobian, q columns times T
    const SpMat Kq = fromTriplets(nv, L.nq, blockOf(J, L.v, nv, L.q, L.nq));
    const SpMat Gt = fromTriplets(nv, m, blockOf(J, L.v, nv, L.lambda, m));
    const SpMat Gq = fromTriplets(m, L.nq, blockOf(J, L.lambda, m, L.q, L.nq));
    const SpMat KT = Kq * T, GT = Gq * T;
    Triplets a;
    const auto put = [&](const SpMat& S, int r0, int c0) {
      for (int j = 0; j < S.outerSize(); ++j) {
        for (SpMat::InnerIterator e(S, j); e; ++e) a.emplace_back(r0 + e.row(), c0 + j, e.value());
      }
    };
    put(KT, 0, 0);
    put(Gt, 0, nv);
    put(GT, nv, 0);
    const SpMat A = fromTriplets(nv + m, nv + m, a);
    Eigen::SparseLU<SpMat> lu(A);
    if (lu.info() != Eigen::Success) {
      throw ModelError("steady motion: the tangent [K G^T; G 0] is singular (no stiffness holds the state: a free "
                       "body, or a mechanism without restoring force)");
    }
    VecX r(nv + m);
    r << F.segment(L.v, nv), F.segment(L.lambda, m);
    const VecX d = lu.solve(-r);
    if (!d.allFinite()) throw ModelError("steady motion: the Newton correction is not finite");
    q = sys.applyIncrement(q, d.head(nv));
    lambda += d.tail(m);
    step = d.head(nv).lpNorm<Eigen::Infinity>();
    if (step <= kTolerance * (1.0 + q.lpNorm<Eigen::Infinity>())) {
      ReferenceState s;
      s.t = t0;
      const ConsistentState v = computeConsistentState(sys, t0, q, c.v);
      s.q = v.q;
      s.v = v.v;
      computeAccelerations(sys, t0, s.q, s.v, s.a, s.lambda);
      return s;
    }
  }
  throw ModelError("steady motion: Newton did not converge in " + std::to_string(kMaxIterations) +
                   " iterations (last correction " + std::to_string(step) + ")");
}

LinearizedSystem linearize(const System& sys, const ReferenceState& state) {
  checkState(sys, state);
  const int nq = sys.numCoordinates(), nv = sys.numVelocities(), m = sys.numConstraintEquations();
  // The DAE Jacobian (index-3 form, y = [q, v, lambda]) at cj = 0 and 1: its F_v rows hold
  // d(M a)/dq - dQ/dq + sum lambda_a H_a (q columns), -dQ/dv + cj M (v columns).
  const DaeSystem dae(sys, Formulation::Index3);
  const DaeLayout& L = dae.layout();
  VecX y, yp;
  dae.packState(state.q, state.v, state.a, state.lambda, y, yp);
  Triplets J0, J1;
  JacobianSink s0 = JacobianSink::recorder(&J0), s1 = JacobianSink::recorder(&J1);
  dae.jacobian(state.t, y.data(), yp.data(), 0.0, s0);
  dae.jacobian(state.t, y.data(), yp.data(), 1.0, s1);
  const SpMat Kq = fromTriplets(nv, nq, blockOf(J0, L.v, nv, L.q, nq));
  const SpMat Cv = fromTriplets(nv, nv, blockOf(J0, L.v, nv, L.v, nv));
  Triplets mass = blockOf(J1, L.v, nv, L.v, nv);
  const Triplets minusJ0 = blockOf(J0, L.v, nv, L.v, nv, -1.0);
  mass.insert(mass.end(), minusJ0.begin(), minusJ0.end());

  LinearizedSystem lin;
  lin.M = fromTriplets(nv, nv, mass);
  lin.M.prune(0.0);
  const SpMat T = rateMatrix(sys, state.q, false), Tinv = rateMatrix(sys, state.q, true);
  lin.B = kinematicTerm(sys, state.q, state.v, T, Tinv);
  lin.C = Cv - lin.M * lin.B;  // dv = dx' - B dx
  lin.K = Kq * T - Cv * lin.B;
  const SpMat A = augmentedMatrix(sys, state.q);
  lin.G = A.block(nv, 0, m, nv);
  lin.velocityNames = sys.velocityNames();
  lin.velocityKinds = sys.velocityKinds();
  // the rates of G along the reference motion q(t) = q (+) t v (exact for constant v):
  // G' analytic, G'' by a central difference of G' along it (the one numerical
  // derivative, a third derivative of the constraints, as in the index-1 Jacobian)
  const double speed = state.v.lpNorm<Eigen::Infinity>();
  if (m > 0 && speed > 0.0) {
    const double h = kRateDifferenceStep / speed;
    const MatX rate = constraintJacobianRate(sys, state.q, state.v);
    const MatX plus = constraintJacobianRate(sys, sys.applyIncrement(state.q, h * state.v), state.v);
    const MatX minus = constraintJacobianRate(sys, sys.applyIncrement(state.q, -h * state.v), state.v);
    lin.Gdot = rate.sparseView(1e-300);
    lin.Gddot = ((plus - minus) / (2.0 * h)).sparseView(1e-300);
  } else {
    lin.Gdot = SpMat(m, nv);
    lin.Gddot = SpMat(m, nv);
  }
  return lin;
}

namespace {

/// Z with G Z = Y (Y m x k), zero on the rows not in `dep` (the dependent velocities of
/// coordinate partitioning): the right inverse R of G applied to Y, sparse.
class PartitionedSolve {
 public:
  PartitionedSolve(const MatX& G, const std::vector<int>& dep) : dep_(dep), nv_(static_cast<int>(G.cols())) {
    MatX Gd(G.rows(), static_cast<Eigen::Index>(dep.size()));
    for (size_t k = 0; k < dep.size(); ++k) Gd.col(static_cast<Eigen::Index>(k)) = G.col(dep[k]);
    qr_.compute(Gd);
  }
  SpMat operator()(const MatX& Y) const {
    const MatX Zd = qr_.solve(Y);
    Triplets t;
    for (size_t k = 0; k < dep_.size(); ++k) {
      for (Eigen::Index j = 0; j < Zd.cols(); ++j) {
        if (Zd(static_cast<Eigen::Index>(k), j) != 0.0) t.emplace_back(dep_[k], j, Zd(static_cast<Eigen::Index>(k), j));
      }
    }
    return fromTriplets(nv_, static_cast<int>(Y.cols()), t);
  }

 private:
  std::vector<int> dep_;
  int nv_;
  Eigen::ColPivHouseholderQR<MatX> qr_;
};

/// Mr, Cr, Kr of `lin` in the basis red.N (set, with red.rank): N^T M N, N^T C N, N^T K N
/// when G is constant along the reference, otherwise with the rates N', N'' of the basis
/// that follows G (reduce()); `dep` the dependent velocities of coordinate partitioning
/// (found here if empty and needed).
void reduceInBasis(const LinearizedSystem& lin, std::vector<int> dep, ReducedSystem& red) {
  const MatX G = lin.G;
  const SpMat Nt = red.N.transpose();
  red.M = Nt * lin.M * red.N;
  if (lin.Gdot.nonZeros() == 0 && lin.Gddot.nonZeros() == 0) {  // G constant along the reference: N constant
    red.C = Nt * lin.C * red.N;
    red.K = Nt * lin.K * red.N;
    return;
  }
  // G changes along the reference motion: dx = N(t) x with G N = 0 at all times, so
  // N' = -R G' N and N'' = -R (2 G' N' + G'' N), R a right inverse of G (the dependent rows
  // of coordinate partitioning, or the pseudo-inverse); then (docs/modes.md)
  //   Mr x'' + N^T (2 M N' + C N) x' + N^T (M N'' + C N' + K N) x = 0.
  // R: the dependent rows of coordinate partitioning for either basis. The family N(t) it
  // defines is N_p(t) C (N_p the partitioning basis, C = const): its independent
  // coordinates are velocity-space increments of the bodies (body-axes rotations, elastic
  // coordinates), in which a steady motion's coefficients do not change with time. A
  // pseudo-inverse would mix world-axes translations into them, turning with the motion.
  if (dep.empty() && red.rank > 0) {
    int rank = 0;
    partitioningBasis(G, lin.velocityKinds, rank, dep);
  }
  // Z with G Z = Y (m x nx), zero on the independent rows: sparse, its m dependent rows dense
  const PartitionedSolve solveG(G, dep);
  const SpMat& N = red.N;
  const SpMat N1 = -solveG(MatX(lin.Gdot * N));
  const SpMat N2 = -solveG(MatX(2.0 * (lin.Gdot * N1) + lin.Gddot * N));
  red.C = Nt * (2.0 * (lin.M * N1) + lin.C * N);
  red.K = Nt * (lin.M * N2 + lin.C * N1 + lin.K * N);
}

}  // namespace

ReducedSystem reduce(const LinearizedSystem& lin, BasisKind basis) {
  ReducedSystem red;
  const MatX G = lin.G;
  std::vector<int> dep;
  red.N = basis == BasisKind::Svd ? svdBasis(G, red.rank) : partitioningBasis(G, lin.velocityKinds, red.rank, dep);
  if (red.N.cols() == 0) throw ModelError("modes: every velocity is constrained (the model has no degree of freedom)");
  reduceInBasis(lin, std::move(dep), red);
  return red;
}

std::vector<int> dependentVelocities(const LinearizedSystem& lin) {
  int rank = 0;
  std::vector<int> dep;
  partitioningBasis(MatX(lin.G), lin.velocityKinds, rank, dep);
  return dep;
}

ReducedSystem reduceNear(const LinearizedSystem& lin, const SpMat& near, const std::vector<int>& dependent) {
  if (near.rows() != lin.M.rows()) {
    throw InputError("reduceNear: the basis has " + std::to_string(near.rows()) + " rows, the linearisation " +
                     std::to_string(lin.M.rows()) + " velocities");
  }
  ReducedSystem red;
  red.rank = static_cast<int>(near.rows() - near.cols());
  // N = N0 - R (G N0): G N = 0 (R the right inverse of G on the dependent columns); smooth
  // in G, and N0 itself where G N0 = 0
  if (dependent.empty()) {
    red.N = near;  // no constraint (or none independent): every velocity is free
  } else {
    const PartitionedSolve solveG(MatX(lin.G), dependent);
    red.N = near - solveG(MatX(lin.G * near));
  }
  reduceInBasis(lin, dependent, red);
  return red;
}

std::vector<Mode> computeModes(const ReducedSystem& red, const ModesOptions& options) {
  if (options.count < 1) throw InputError("modes: the number of modes must be >= 1, got " + std::to_string(options.count));
  const int n = static_cast<int>(red.M.rows());
  const bool dense = options.solver == EigenSolverKind::Dense ||
                     (options.solver == EigenSolverKind::Automatic && n <= kDenseModesLimit) || 2 * n < 8;
  checkDampingScale(red);
  return dense ? denseModes(red, options.count) : sparseModes(red, options.count, options.shift);
}

std::vector<Mode> modesAbout(const System& sys, const ReferenceState& state, const ModesOptions& options,
                             BasisKind basis) {
  return computeModes(reduce(linearize(sys, state), basis), options);
}

double modalAssurance(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  const double aa = a.squaredNorm(), bb = b.squaredNorm();
  if (!(aa > 0.0) || !(bb > 0.0) || a.size() != b.size()) return 0.0;
  return std::norm(a.dot(b)) / (aa * bb);  // a.dot(b) = a^H b
}

std::vector<int> followBranches(const std::vector<Mode>& previous, const std::vector<Mode>& current) {
  const int np = static_cast<int>(previous.size()), nc = static_cast<int>(current.size());
  std::vector<std::tuple<double, int, int>> pairs;  // (MAC, previous, current)
  for (int i = 0; i < np; ++i)
    for (int j = 0; j < nc; ++j) pairs.emplace_back(modalAssurance(previous[i].shape, current[j].shape), i, j);
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const auto& x, const auto& y) { return std::get<0>(x) > std::get<0>(y); });
  std::vector<int> of(np, -1);
  std::vector<char> used(nc, 0);
  for (const auto& [mac, i, j] : pairs) {
    if (mac < kBranchAssurance) break;  // not the same shape: left to the frequency order
    if (of[i] < 0 && !used[j]) {
      of[i] = j;
      used[j] = 1;
    }
  }
  // branches without a confident match (a degenerate pair splitting, a shape that changed
  // too much between two speeds) take the modes left over in frequency order
  int next = 0;
  for (int i = 0; i < np; ++i) {
    if (of[i] >= 0) continue;
    while (next < nc && used[next]) ++next;
    if (next < nc) {
      of[i] = next;
      used[next] = 1;
    }
  }
  std::vector<int> order;
  for (int i = 0; i < np; ++i) {
    if (of[i] >= 0) order.push_back(of[i]);
  }
  for (int j = 0; j < nc; ++j) {  // modes of no earlier branch: by frequency (current's order)
    if (!used[j]) order.push_back(j);
  }
  return order;
}

}  // namespace flexmbd
