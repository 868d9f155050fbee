// Structure that keeps the cost of large models linear: the kinematic matrix
// T(q) of a spatial flexible body written through its structural non-zeros only, a
// Jacobian pattern and factors that grow linearly with the mesh and with a chain of
// flexible links, and the KLU ordering chosen per model by trial factorisations. These
// are counts, not timings: a dense block or a quadratic fill fails them on any machine.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "bodies/ffr_body_3d.hpp"
#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/klu_ordering.hpp"
#include "scene/scene.hpp"
#include "problems/ffr_test_models.hpp"

using namespace flexmbd;

namespace {

Scene spatialCrank(int elements) { return parseScene(testmodels::spatialElasticCrankJson(elements)); }

Scene chain(int links) { return parseScene(testmodels::flexibleChainJson(links)); }

/// The DAE of a scene at its consistent initial state, and the ordering KLU gets.
struct Factored {
  int size = 0;
  int64_t patternNonZeros = 0;
  KluOrdering ordering;
};

Factored factor(const Scene& s) {
  const System& sys = s.system;
  const ConsistentState init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  VecX y, yp;
  dae.packState(init.q, init.v, init.a, init.lambda, y, yp);
  return {dae.size(), dae.pattern().nonZeros(), KluOrdering::choose(dae, 0.0, y, yp, kOrderingTrialCj)};
}

// Linear growth doubles the counts with the model; a quadratic one quadruples them. The
// bound 2.4 between consecutive doublings leaves room for the fixed part of the model
// (crank, slider, joints: the ratio of a linear count is below 2 + that part's share).
constexpr double kLinearDoublingBound = 2.4;

}  // namespace

TEST(SparsityScaling, SpatialFlexibleRateMatrixHasOnlyItsStructuralNonZeros) {
  // T = diag(I3, 1/2 L(p)^T, I_nf): 3 + 12 + nf entries, the dense form agreeing
  const Scene s = spatialCrank(8);
  const System& sys = s.system;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const auto* flex = dynamic_cast<const FfrBody3d*>(&body);
    if (!flex) continue;
    const VecX q = body.initialCoordinates();
    std::vector<Eigen::Triplet<double>> written;
    JacobianSink recorder = JacobianSink::recorder(&written);
    body.addCoordinateRateMatrix(q, MatrixSink(recorder, 0, 0));
    EXPECT_EQ(static_cast<int>(written.size()), 15 + flex->numElastic());
    MatX T;
    body.coordinateRateMatrix(q, T);
    MatX Tinv;
    body.coordinateRateInverse(q, Tinv);
    // T+ T = I on the velocities (round-off of the unit quaternion: 1e-14)
    EXPECT_LT((Tinv * T - MatX::Identity(body.numVelocities(), body.numVelocities())).cwiseAbs().maxCoeff(), 1e-14);
    return;
  }
  FAIL() << "no spatial flexible body in the scene";
}

TEST(SparsityScaling, SpatialNodalJacobianPatternGrowsLinearlyWithTheMesh) {
  int64_t previous = 0;
  for (int n : {16, 32, 64}) {
    const Scene s = spatialCrank(n);
    const DaeSystem dae(s.system, Formulation::Ggl);
    const int64_t nnz = dae.pattern().nonZeros();
    if (previous > 0) {
      EXPECT_LT(static_cast<double>(nnz) / static_cast<double>(previous), kLinearDoublingBound) << n << " elements";
    }
    previous = nnz;
  }
}

TEST(SparsityScaling, FactorsOfASpatialRodAndOfAChainGrowLinearly) {
  // the chosen ordering's nnz(L + U) doubles with the model: a rod of 16 -> 64 elements,
  // a chain of 8 -> 32 links (with one fixed ordering one of the two filled quadratically)
  int64_t previous = 0;
  for (int n : {16, 32, 64}) {
    const Factored f = factor(spatialCrank(n));
    ASSERT_GT(f.ordering.factorNonZeros(), 0);
    if (previous > 0) {
      EXPECT_LT(static_cast<double>(f.ordering.factorNonZeros()) / static_cast<double>(previous), kLinearDoublingBound)
          << n << " elements, ordering " << f.ordering.name();
    }
    previous = f.ordering.factorNonZeros();
  }
  previous = 0;
  for (int n : {8, 16, 32}) {
    const Factored f = factor(chain(n));
    if (previous > 0) {
      EXPECT_LT(static_cast<double>(f.ordering.factorNonZeros()) / static_cast<double>(previous), kLinearDoublingBound)
          << n << " links, ordering " << f.ordering.name();
    }
    previous = f.ordering.factorNonZeros();
  }
}

TEST(SparsityScaling, OrderingChoiceKeepsTheSparsestCandidate) {
  // A chain takes KLU's own ordering (frames and multipliers last fill it quadratically),
  // and its chosen factors are no larger than those of each constrained order.
  const Scene s = chain(16);
  const System& sys = s.system;
  const ConsistentState init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  VecX y, yp;
  dae.packState(init.q, init.v, init.a, init.lambda, y, yp);
  const KluOrdering chosen = KluOrdering::choose(dae, 0.0, y, yp, kOrderingTrialCj);
  EXPECT_EQ(chosen.kind(), KluOrdering::Kind::KluDefault);
  // a rigid model (no elastic coordinates) keeps KLU's own ordering without trials
  const Scene rigid = parseScene(nlohmann::json{
      {"bodies", {{{"name", "bar"}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", 0.1}, {"position", {0.5, 0.0}}}}},
      {"joints", {{{"name", "pin"}, {"type", "revolute"}, {"bodies", {"ground", "bar"}}, {"points", {{0.0, 0.0}, {-0.5, 0.0}}}}}},
      {"gravity", {0.0, -9.81}}});
  const Factored r = factor(rigid);
  EXPECT_EQ(r.ordering.kind(), KluOrdering::Kind::KluDefault);
  EXPECT_EQ(r.ordering.factorNonZeros(), 0);
  // a long rod takes a constrained order
  EXPECT_NE(factor(spatialCrank(64)).ordering.kind(), KluOrdering::Kind::KluDefault);
}
