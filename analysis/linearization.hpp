/// @file
/// Linearisation of the constrained equations of motion about a state, and modal analysis
/// of the result (docs/modes.md). Sources: GeradinCardona2001, ch. 11 "Linearized analysis";
/// Shabana2005, sec. 6.x on the embedding (null-space) technique.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "core/system.hpp"
#include "integrators/initial_conditions.hpp"

namespace flexmbd {

/// The state the equations are linearised about: an equilibrium (v = 0, a = 0) or a
/// steady motion (constant v, e.g. a spin). a and lambda: accelerations and multipliers
/// consistent with (t, q, v) (computeAccelerations, or solveStaticEquilibrium with a = 0).
struct ReferenceState {
  double t = 0.0;
  VecX q, v, a, lambda;
};

/// The consistent state at t0 from the system's initial values: positions projected on
/// the constraints, velocities on the velocity constraints; if the velocities are then
/// all zero, the static equilibrium is solved from there (a = 0, its multipliers; planar
/// and spatial models, solveStaticEquilibrium);
/// otherwise accelerations and multipliers come from the augmented system.
/// `released`: redundant constraints (as a run's "redundant_constraints"; default: refused,
/// a ModelError naming them): the equations released at the consistent state are released
/// in the static solve too (their multipliers 0; the linearisation's null-space basis
/// handles the rank of G by itself).
/// @throws ModelError if the model cannot be assembled or has no equilibrium.
ReferenceState referenceStateAt(const System& sys, double t0, const VecX& q0, const VecX& v0,
                                const ReleasedEquations& released = {});

/// A steady motion with constant velocities and zero accelerations (a rotor at constant
/// speed with its frame origin on the axis, stretched by the centrifugal load): from the
/// consistent state at t0, Newton iterations on [M 0 - Q(t, q, v) + G^T lambda; g(q, t)] = 0
/// for q (velocity-space increments, q (+) dx) and lambda at the fixed velocities v, with
/// the tangent [Kq T, G^T; G, 0] of the DAE Jacobian; then the velocities projected on
/// the constraints again and a, lambda recomputed (a ~ 0 when the motion is steady).
/// @throws ModelError naming the residual if it does not converge or the tangent is singular
/// (a free body: no stiffness holds its position; use referenceStateAt).
ReferenceState solveSteadyMotion(const System& sys, double t0, const VecX& q0, const VecX& v0);

/// The linearised equations in velocity space (nv unknowns; increments dq = T(q) dx,
/// q = q_ref (+) dx, Body::applyIncrement), frozen at the reference state:
///   M dx'' + C dx' + K dx + G^T dlambda = 0,   G dx = 0,
/// with (GeradinCardona2001, sec. 11.2; B the kinematic term below)
///   M = M(q),  C = -dQ/dv - M B,  K = (d(M a)/dq - dQ/dq + sum_a lambda_a dG_a^T/dq) T - (-dQ/dv) B,
/// where B dx = T+ (d(T v)/dq T dx - d(T dx)/dq T v) is the rate of a velocity-space
/// increment carried by the reference motion: dx' = dv + B dx (zero when T = I, the
/// Lie bracket -w x dx of body-axes rotations of spatial bodies).
/// Every block is assembled from the DAE Jacobian (DaeSystem) and the constraints'
/// analytic Jacobians; nothing is differentiated numerically.
struct LinearizedSystem {
  SpMat M, C, K;  ///< nv x nv
  SpMat G;        ///< m x nv, the velocity Jacobian of the constraints at q
  SpMat B;        ///< nv x nv, the kinematic term (zero for planar models)
  /// G' and G'' (m x nv): the rates of G along the reference motion q (+) t v (zero at
  /// rest); reduce() keeps the basis N(t) in the null space of G(t) with them.
  SpMat Gdot, Gddot;
  std::vector<std::string> velocityNames;
  std::vector<CoordinateKind> velocityKinds;
};

/// @throws InputError if the system is not finalized or the state has wrong sizes.
LinearizedSystem linearize(const System& sys, const ReferenceState& state);

/// A basis N (nv x nx, nx = nv - rank G) of the null space of G: the independent
/// coordinates x with dx = N x (the embedding technique, Shabana2005, sec. 6.x).
enum class BasisKind {
  Svd,                    ///< orthonormal (dense SVD): small systems
  CoordinatePartitioning  ///< dx = [x; -G_d^-1 G_i x] (rows permuted): sparse, frame coordinates dependent first
};

/// The reduced equations Mr x'' + Cr x' + Kr x = 0 and N: Mr = N^T M N, Cr = N^T C N,
/// Kr = N^T K N when G is constant along the reference (the embedding, Shabana2005, sec. 6.x;
/// GeradinCardona2001, ch. 11); otherwise dx = N(t) x with
/// N' = -R G' N, N'' = -R (2 G' N' + G'' N) (R the right inverse of G of coordinate
/// partitioning: body-axes increments stay the independent coordinates) and
/// Cr = N^T (2 M N' + C N), Kr = N^T (M N'' + C N' + K N) (docs/modes.md).
struct ReducedSystem {
  SpMat M, C, K;  ///< nx x nx
  SpMat N;        ///< nv x nx
  int rank = 0;   ///< rank of G found (numerical, relative tolerance 1e-10)
};
/// @throws ModelError if every velocity is constrained (nothing moves).
ReducedSystem reduce(const LinearizedSystem& lin, BasisKind basis = BasisKind::Svd);

/// The velocities coordinate partitioning takes as dependent for lin.G (pivoted QR with
/// elastic columns weighted, as reduce() chooses them), ascending: one per independent
/// constraint equation.
std::vector<int> dependentVelocities(const LinearizedSystem& lin);

/// The reduced equations of `lin` in the basis `near` (nv x nx, e.g. reduce()'s N of a
/// neighbouring linearisation) moved onto the null space of lin.G: N = N0 - R (G N0), R the
/// right inverse of G on the `dependent` velocities (zero on the others), so that G N = 0;
/// N = N0 where G N0 = 0 already. N is a smooth function of G: the reduced matrices of
/// linearisations at p + h and p - h in the bases moved from one N0 differ by O(h), which
/// is what their central differences need (the eigenvalue sensitivities,
/// sensitivity/modal_sensitivity.hpp). @pre N0 spans a complement of the null space's
/// orthogonal complement (true for a basis of a nearby G's null space).
ReducedSystem reduceNear(const LinearizedSystem& lin, const SpMat& near, const std::vector<int>& dependent);

/// One eigenvalue s of the first-order form [0 I; -Mr^-1 Kr, -Mr^-1 Cr] and its mode.
struct Mode {
  std::complex<double> eigenvalue;   ///< s = -zeta omega + i omega sqrt(1 - zeta^2) (GeradinRixen)
  double omega = 0.0;                ///< |s| (rad/s): the undamped natural frequency for light damping
  double frequencyHz = 0.0;          ///< omega / (2 pi)
  double dampingRatio = 0.0;         ///< -Re(s) / |s| (0 for s = 0; -1 for a real positive s)
  Eigen::VectorXcd shape;            ///< velocity space (nv): N x, largest entry 1 (real)
};

enum class EigenSolverKind {
  Automatic,  ///< dense up to kDenseModesLimit independent coordinates, sparse above
  Dense,      ///< Eigen::EigenSolver on the 2 nx first-order matrix
  Sparse      ///< Spectra shift-invert (GenEigsRealShiftSolver) about `shift`
};
inline constexpr int kDenseModesLimit = 400;

struct ModesOptions {
  int count = 10;  ///< modes returned (eigenvalues with Im s >= 0, by increasing |s|)
  EigenSolverKind solver = EigenSolverKind::Automatic;
  /// Real shift of the sparse solver: the eigenvalues nearest to it are found. Slightly
  /// negative, so that rigid-body (zero) eigenvalues do not make the shifted matrix singular.
  double shift = -1e-3;
};

/// The `count` lowest modes: eigenvalues with Im s >= 0 (one of each complex pair), by
/// increasing |s|, then increasing Im s.
/// @throws ModelError if the reduced mass matrix is singular; SolverError if an eigensolver
/// does not converge (or the sparse one's shift is an eigenvalue).
std::vector<Mode> computeModes(const ReducedSystem& red, const ModesOptions& options = {});

/// The modal assurance criterion of two mode shapes: |a^H b|^2 / ((a^H a) (b^H b)), 1 for
/// the same shape, 0 for orthogonal ones (AllemangBrown1982).
double modalAssurance(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b);

/// Two modes are taken for the same branch when their modal assurance is at least this
/// (a shape that changed more between two speeds, or a degenerate pair that splits, whose
/// members match the split modes at about 0.5 each, is left to the frequency order).
inline constexpr double kBranchAssurance = 0.8;

/// The branches of a sweep followed by shape, not by rank (a Campbell diagram whose modes
/// cross): for each mode of `previous` (in its order) the index of the mode of `current`
/// with the same shape, the pairs taken greedily by decreasing modal assurance (each mode of
/// `current` used once, none below kBranchAssurance); the branches left take the modes left
/// in frequency order, and the modes of `current` left over follow, by frequency. Returns a
/// permutation of 0 .. current.size() - 1.
std::vector<int> followBranches(const std::vector<Mode>& previous, const std::vector<Mode>& current);

/// Linearisation, reduction and modes in one call.
std::vector<Mode> modesAbout(const System& sys, const ReferenceState& state, const ModesOptions& options = {},
                             BasisKind basis = BasisKind::Svd);

}  // namespace flexmbd
