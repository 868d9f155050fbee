// Contact between members as a unilateral constraint in the LCP of method 1
// (TimeSteppingSettings::contactConstraints, scene key solver.contact_constraints).
#include <gtest/gtest.h>

#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;

namespace {

// Fixed strut A along x at z = 0 (nodes (+-1, 0, 0)); strut B along y at height z0
// (nodes (0, +-1, z0)), mass 1 per node, both nodes moving down at speed V. Radii r each:
// contact when z = 2r, at t* = (z0 - 2r)/V. No gravity unless g != 0.
TensegrityStructure sweptStrut(double z0, double V, double r, double g) {
  TensegrityStructure s(3);
  s.addNode("a1", Eigen::Vector3d(-1, 0, 0), 0.0, {true, true, true}, Eigen::Vector3d::Zero());
  s.addNode("a2", Eigen::Vector3d(1, 0, 0), 0.0, {true, true, true}, Eigen::Vector3d::Zero());
  s.addNode("b1", Eigen::Vector3d(0, -1, z0), 1.0, {}, Eigen::Vector3d(0, 0, -V));
  s.addNode("b2", Eigen::Vector3d(0, 1, z0), 1.0, {}, Eigen::Vector3d(0, 0, -V));
  s.addStrut("A", 0, 1, 1e6, 2.0, 0.0, BarMassModel::Lumped, r);
  s.addStrut("B", 2, 3, 1e6, 2.0, 0.0, BarMassModel::Lumped, r);
  s.setGravity(Eigen::Vector3d(0, 0, -g));
  s.finalize();
  return s;
}

struct RunResult {
  TensegrityRunSummary sum;
  VecX x, v;
};

RunResult simulate(const TensegrityStructure& s, double tEnd, bool constraints) {
  TimeSteppingSettings set;
  set.tEnd = tEnd;
  set.timeStep = 1e-3;
  set.lcp.tolerance = 1e-12;
  set.detectContacts = true;
  set.contactConstraints = constraints;
  RunResult r;
  TensegrityObserver obs;
  obs.onSample = [&](const TensegritySample& smp) {
    r.x = smp.x;
    r.v = smp.v;
  };
  r.sum = TensegrityTimeStepper(s, set).run(obs);
  return r;
}

}  // namespace

TEST(TensegrityContactConstraint, SweptStrutStopsOnFixedStrut) {
  const double z0 = 1.0, V = 1.0, r = 0.05;  // contact at t* = 0.9, z = 0.1
  const TensegrityStructure s = sweptStrut(z0, V, r, 0.0);
  // Without the option the members pass through each other (only reported).
  const RunResult passing = simulate(s, 1.5, false);
  ASSERT_TRUE(passing.sum.ok) << passing.sum.message;
  EXPECT_EQ(passing.sum.contacts, 1);
  EXPECT_NEAR(passing.x[8], z0 - 1.5 * V, 1e-9);  // free flight, only round-off
  // With it: an inelastic impact at t* (rate-form constraint, w = 0 after the step).
  const RunResult c = simulate(s, 1.5, true);
  ASSERT_TRUE(c.sum.ok) << c.sum.message;
  EXPECT_EQ(c.sum.contacts, 1);
  // Impulse: the whole momentum 2 m V = 2 is removed (both nodes, contact at B's middle).
  // Tolerance: the LCP acceptance tolerance 1e-12 times |q| ~ 1, with margin.
  constexpr double kImpulseTol = 1e-9;
  EXPECT_NEAR(c.sum.contactImpulseSum, 2.0 * V, kImpulseTol);
  // After the contact: normal relative velocity zero (LCP w = 0 to its tolerance; the
  // projection changes positions, not velocities).
  constexpr double kVelTol = 1e-9;
  EXPECT_NEAR(c.v[8], 0.0, kVelTol);
  EXPECT_NEAR(c.v[11], 0.0, kVelTol);
  // No penetration: B rests at z = 2r; the penetration of the activation step (at most
  // V dt) is projected out to projection_tolerance (1e-12 relative to the mean member
  // length 2): 1e-10 absolute with margin.
  constexpr double kGapTol = 1e-10;
  EXPECT_NEAR(c.x[8], 2 * r, kGapTol);
  EXPECT_NEAR(c.x[11], 2 * r, kGapTol);
  EXPECT_GE(c.x[8], 2 * r - kGapTol);
  EXPECT_LE(c.sum.maxDriftAfterProjection, 1e-12);
}

TEST(TensegrityContactConstraint, RestingStrutCarriesItsWeight) {
  // B starts touching A (z0 = 2r, at rest) under gravity g: it must stay there, the
  // contact impulse per step being the weight 2 m g dt, i.e. sum = 2 m g t_end.
  const double r = 0.05, g = 9.81, tEnd = 0.2;
  const TensegrityStructure s = sweptStrut(2 * r, 0.0, r, g);
  const RunResult c = simulate(s, tEnd, true);
  ASSERT_TRUE(c.sum.ok) << c.sum.message;
  // Impulse sum: 200 LCPs each accepted to 1e-12 (relative to 1 + |q|, |q| ~ g dt).
  EXPECT_NEAR(c.sum.contactImpulseSum, 2.0 * g * tEnd, 1e-9);
  EXPECT_NEAR(c.x[8], 2 * r, 1e-10);  // as in the swept case (projection tolerance)
  EXPECT_NEAR(c.v[8], 0.0, 1e-9);     // rate constraint w = 0 to the LCP tolerance
}
