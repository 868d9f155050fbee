// LCP solvers behind tensegrity/lcp_solver.hpp (Siconos lexicographic Lemke and
// projected Gauss-Seidel) on a closed-form 2x2 case and on the Delassus LCPs of the
// tensegrity time-stepper, compared with each other; and the stepper run with both.
#include <gtest/gtest.h>

#include <malloc.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "tensegrity/lcp_solver.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;

namespace {

// Requested LCP acceptance tolerance (relative natural-map residual, see LcpSolution).
constexpr double kLcpTol = 1e-12;
// Closed form vs solver: Lemke is a pivoting method (exact up to round-off on a 2x2);
// PGS stops when Siconos' own error is below kLcpTol, so its z is accurate to about
// kLcpTol * cond(M) (cond = 3 here): 1e-11 covers both with margin.
constexpr double kClosedFormTol = 1e-11;

LcpSolution solveWith(LcpMethod m, const MatX& M, const VecX& q) {
  LcpOptions o;
  o.method = m;
  o.tolerance = kLcpTol;
  o.maxIterations = 100000;
  return LcpSolver(o).solve(M, q);
}

// k x k cable net (spacing 1, mass 1 per node, corners fixed), random velocities: the
// stepper's first LCP, W = B M^-1 B^T over all cables, q = -B v.
void netLcp(int k, unsigned seed, MatX& W, VecX& q) {
  TensegrityStructure s(3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const bool corner = (i == 0 || i == k - 1) && (j == 0 || j == k - 1);
      const Eigen::Vector3d v = corner ? Eigen::Vector3d::Zero() : Eigen::Vector3d(u(rng), u(rng), u(rng));
      s.addNode("n" + std::to_string(i * k + j), Eigen::Vector3d(i, j, 0.1 * u(rng)), 1.0 + 0.5 * u(rng),
                std::vector<bool>(3, corner), v);
    }
  }
  const VecX x0 = s.initialPositions();
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const int a = i * k + j;
      if (i + 1 < k) s.addCable("h" + std::to_string(a), a, a + k, 0.0, 1.0, true);
      if (j + 1 < k) s.addCable("v" + std::to_string(a), a, a + 1, 0.0, 1.0, true);
    }
  }
  s.finalize();
  const int nc = s.numCables(), nf = s.numFreeCoordinates();
  MatX B(nc, nf);
  for (int c = 0; c < nc; ++c) B.row(c) = s.cableGradientFree(x0, c);
  const MatX Minv = s.massMatrix().inverse();
  W = B * Minv * B.transpose();
  q = -B * s.restrict(s.initialVelocities());
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__)
#define FLEXMBD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FLEXMBD_ASAN 1
#endif
#endif

// Every solve created Siconos SolverOptions and freed only their
// contents (120 bytes lost per solve: 1.2 MB over 10,000 solves). The heap in use
// (glibc mallinfo2) must not grow with the number of solves or of solvers. Bound: 64 KB,
// room for allocator bookkeeping, 1/19 of what the leak lost here.
TEST(LcpSolver, RepeatedSolvesAndSolversDoNotGrowTheHeap) {
#ifdef FLEXMBD_ASAN
  GTEST_SKIP() << "AddressSanitizer replaces malloc (mallinfo2 reads 0); LeakSanitizer checks this build";
#else
  constexpr long kSolves = 10000;
  constexpr long kMaxGrowthBytes = 64 * 1024;
  MatX M(2, 2);
  M << 2.0, 1.0, 1.0, 2.0;
  const VecX q = VecX::Constant(2, -1.0);
  for (const LcpMethod m : {LcpMethod::Lemke, LcpMethod::ProjectedGaussSeidel}) {
    LcpOptions o;
    o.method = m;
    o.tolerance = kLcpTol;
    (void)LcpSolver(o).solve(M, q);  // first-use allocations of Siconos (if any) before the baseline
    const LcpSolver solver(o);
    const long before = static_cast<long>(mallinfo2().uordblks);
    for (long k = 0; k < kSolves; ++k) ASSERT_TRUE(solver.solve(M, q).ok);
    const long afterSolves = static_cast<long>(mallinfo2().uordblks);
    for (long k = 0; k < kSolves; ++k) (void)LcpSolver(o);
    const long afterSolvers = static_cast<long>(mallinfo2().uordblks);
    EXPECT_LT(afterSolves - before, kMaxGrowthBytes) << toString(m) << ": heap growth over " << kSolves << " solves";
    EXPECT_LT(afterSolvers - afterSolves, kMaxGrowthBytes)
        << toString(m) << ": heap growth over " << kSolves << " solver objects";
  }
#endif
}

TEST(TensegrityLcp, ClosedForm2x2BothSolvers) {
  // M = [2 1; 1 2] (symmetric positive definite, like a Delassus matrix).
  MatX M(2, 2);
  M << 2, 1, 1, 2;
  // q = (-1, -1): both active, z = M^-1 (1, 1) = (1/3, 1/3), w = 0.
  // q = (-1, 1): z = (1/2, 0), w = (0, 1 + 1/2).
  const VecX qs[2] = {(VecX(2) << -1, -1).finished(), (VecX(2) << -1, 1).finished()};
  const VecX zs[2] = {(VecX(2) << 1.0 / 3, 1.0 / 3).finished(), (VecX(2) << 0.5, 0.0).finished()};
  const VecX ws[2] = {VecX::Zero(2), (VecX(2) << 0.0, 1.5).finished()};
  for (LcpMethod m : {LcpMethod::Lemke, LcpMethod::ProjectedGaussSeidel}) {
    for (int c = 0; c < 2; ++c) {
      const LcpSolution sol = solveWith(m, M, qs[c]);
      EXPECT_TRUE(sol.ok) << toString(m) << " info " << sol.info << " residual " << sol.residual;
      EXPECT_EQ(sol.info, 0) << toString(m);
      EXPECT_LT((sol.z - zs[c]).lpNorm<Eigen::Infinity>(), kClosedFormTol) << toString(m);
      EXPECT_LT((sol.w - ws[c]).lpNorm<Eigen::Infinity>(), kClosedFormTol) << toString(m);
    }
  }
}

// The matrix that used to make lcp_pgs return info 2: non-symmetric storage would be
// read transposed, so the test also uses a non-symmetric P-matrix whose solution differs
// from the one of its transpose.
TEST(TensegrityLcp, NonSymmetricMatrixIsReadColumnMajor) {
  MatX M(2, 2);
  M << 2, 1, 0, 2;  // z = M^-1 (1, 1) = (1/4, 1/2); with M^T it would be (1/2, 1/4)
  const VecX q = (VecX(2) << -1, -1).finished();
  for (LcpMethod m : {LcpMethod::Lemke, LcpMethod::ProjectedGaussSeidel}) {
    const LcpSolution sol = solveWith(m, M, q);
    EXPECT_TRUE(sol.ok) << toString(m);
    EXPECT_NEAR(sol.z[0], 0.25, kClosedFormTol) << toString(m);
    EXPECT_NEAR(sol.z[1], 0.5, kClosedFormTol) << toString(m);
  }
}

TEST(TensegrityLcp, LemkeAndPgsAgreeOnCableNetLcps) {
  // Delassus LCPs of 4x4 .. 8x8 nets (24 .. 112 cables, W positive definite: the cables
  // of a net with corners fixed are independent). Both solvers must reach the requested
  // residual; z is unique (W positive definite), so they must agree. Tolerance on z:
  // kLcpTol * (1 + |q|) / lambda_min(W) bounds the error of each solver's z from its
  // natural-map residual; 1e-8 absolute is that with lambda_min(W) >= 1e-3 and |q| <= 10
  // (checked below).
  constexpr double kAgreeTol = 1e-8;
  for (int k : {4, 6, 8}) {
    MatX W;
    VecX q;
    netLcp(k, 7u + k, W, q);
    const double lmin = Eigen::SelfAdjointEigenSolver<MatX>(W).eigenvalues().minCoeff();
    ASSERT_GT(lmin, 1e-3) << k;
    ASSERT_LT(q.lpNorm<Eigen::Infinity>(), 10.0) << k;
    const LcpSolution lemke = solveWith(LcpMethod::Lemke, W, q);
    const LcpSolution pgs = solveWith(LcpMethod::ProjectedGaussSeidel, W, q);
    ASSERT_TRUE(lemke.ok) << k << " info " << lemke.info << " residual " << lemke.residual;
    ASSERT_TRUE(pgs.ok) << k << " info " << pgs.info << " residual " << pgs.residual;
    EXPECT_GT((lemke.z.array() > 0.0).count(), 0) << "no active cable: a trivial test";
    EXPECT_LT((lemke.z - pgs.z).lpNorm<Eigen::Infinity>(), kAgreeTol) << k;
  }
}

TEST(TensegrityLcp, StepperRunsWithPgsLikeLemke) {
  // Three masses, two inextensible cables snapping at once (the LcpFailure... case of
  // test_tensegrity_contact_input with normal PGS settings): closed form, equal masses
  // m = 1, v = (-1, 0, 1): one impulse p on both cables, all come to rest; p = 1.
  TensegrityStructure s(2);
  s.addNode("a", Eigen::Vector2d(0, 0), 1.0, {}, Eigen::Vector2d(-1, 0));
  s.addNode("b", Eigen::Vector2d(1, 0), 1.0, {}, Eigen::Vector2d(0, 0));
  s.addNode("c", Eigen::Vector2d(2, 0), 1.0, {}, Eigen::Vector2d(1, 0));
  s.addCable("ab", 0, 1, 0.0, 1.0, true);
  s.addCable("bc", 1, 2, 0.0, 1.0, true);
  s.finalize();
  // Velocities after the snap: 0 exactly with Lemke (pivoting), to the PGS acceptance
  // tolerance times cond(W) = 3 otherwise.
  constexpr double kVelTol = 1e-10;
  for (LcpMethod m : {LcpMethod::Lemke, LcpMethod::ProjectedGaussSeidel}) {
    TimeSteppingSettings set;
    set.tEnd = 0.01;
    set.timeStep = 1e-3;
    set.lcp.method = m;
    set.lcp.tolerance = kLcpTol;
    VecX vEnd;
    TensegrityObserver obs;
    obs.onSample = [&](const TensegritySample& smp) { vEnd = smp.v; };
    const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run(obs);
    ASSERT_TRUE(sum.ok) << toString(m) << ": " << sum.message;
    EXPECT_EQ(sum.snaps, 2) << toString(m);
    EXPECT_LT(vEnd.lpNorm<Eigen::Infinity>(), kVelTol) << toString(m);
  }
}

// What lcp_pgs' info 2 means: a diagonal term below DBL_EPSILON in absolute value (its
// test is |M_ii| < DBL_EPSILON, "negative" in the header is a misnomer); a Delassus
// matrix has one only for a constraint that moves no free coordinate (e.g. a cable
// between two fixed nodes). Lemke solves it; PGS reports the failure.
TEST(TensegrityLcp, PgsInfo2IsAVanishingDiagonal) {
  MatX M(2, 2);
  M << 0, 0, 0, 1;
  const VecX q = (VecX(2) << 1, -1).finished();  // z = (0, 1), w = (1, 0)
  const LcpSolution lemke = solveWith(LcpMethod::Lemke, M, q);
  EXPECT_TRUE(lemke.ok);
  EXPECT_NEAR(lemke.z[1], 1.0, kClosedFormTol);
  const LcpSolution pgs = solveWith(LcpMethod::ProjectedGaussSeidel, M, q);
  EXPECT_FALSE(pgs.ok);
  EXPECT_EQ(pgs.info, 2);
}
