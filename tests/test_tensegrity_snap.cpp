// Cable snaps of tensegrity models (source document 001): the two-mass cable
// snap against its analytic impact solution (method 1), the massless-cable limit
// (method 2), momentum conservation through snaps and the energy balance of both methods.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tensegrity/massless_cable_integrator.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;

namespace {

/// Two masses m1 = 1, m2 = 2 on the x axis joined by a cable of natural length 1, at its
/// natural length, moving apart at relative speed 2 (v1 = 0, v2 = 2).
TensegrityStructure twoMasses(bool inextensible, double ea = 0.0) {
  TensegrityStructure s(2);
  s.addNode("m1", Eigen::Vector2d(0, 0), 1.0, {}, Eigen::Vector2d(0, 0));
  s.addNode("m2", Eigen::Vector2d(1, 0), 2.0, {}, Eigen::Vector2d(2, 0));
  s.addCable("c", 0, 1, ea, 1.0, inextensible);
  s.finalize();
  return s;
}

struct Recorder {
  std::vector<TensegritySample> samples;
  std::vector<TensegrityEvent> events;
  TensegrityObserver observer() {
    return {[this](const TensegritySample& s) { samples.push_back(s); },
            [this](const TensegrityEvent& e) { events.push_back(e); }};
  }
};

Eigen::VectorXd momentum(const TensegrityStructure& s, const TensegritySample& smp) {
  const int d = s.dimension();
  Eigen::VectorXd p = Eigen::VectorXd::Zero(d);
  const Eigen::VectorXd mv = s.fullMassMatrix() * smp.v;
  for (int i = 0; i < s.numNodes(); ++i) p += mv.segment(i * d, d);
  return p;
}

}  // namespace

// Analytic perfectly inelastic impact: impulse = mu v_rel = (2/3) 2 = 4/3, common velocity
// (m2 v2)/(m1 + m2) = 4/3, kinetic energy lost 1/2 mu v_rel^2 = 4/3.
TEST(TensegritySnap, TwoMassInextensibleCableMatchesAnalyticImpact) {
  const TensegrityStructure s = twoMasses(true);
  TimeSteppingSettings set;
  set.tEnd = 0.01;
  set.timeStep = 1e-3;
  Recorder rec;
  const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run(rec.observer());
  ASSERT_TRUE(sum.ok) << sum.message;
  // Tolerance 1e-9: the LCP of a single cable is solved exactly by Lemke; the
  // remaining error is round-off.
  constexpr double kTol = 1e-9;
  ASSERT_EQ(sum.snaps, 1);
  ASSERT_EQ(rec.events.size(), 1u);
  EXPECT_EQ(rec.events[0].type, TensegrityEvent::Type::Snap);
  EXPECT_NEAR(rec.events[0].impulse, 4.0 / 3.0, kTol);
  EXPECT_NEAR(rec.events[0].elongationRate, 2.0, kTol);
  const TensegritySample& last = rec.samples.back();
  EXPECT_NEAR(last.v[0], 4.0 / 3.0, kTol);
  EXPECT_NEAR(last.v[2], 4.0 / 3.0, kTol);
  EXPECT_NEAR(last.v[1], 0.0, kTol);
  EXPECT_NEAR(rec.samples.front().kineticEnergy - last.kineticEnergy, 4.0 / 3.0, kTol);
  EXPECT_NEAR(rec.events[0].energyChange, -4.0 / 3.0, kTol);
  // The cable stays at its natural length after the projection of the drift.
  EXPECT_NEAR(last.cableLength[0], 1.0, kTol);
  EXPECT_GT(sum.maxDriftBeforeProjection, 0.0);  // dt v_rel/2 = 1e-3 overshoot in the snap step
  EXPECT_LE(sum.maxDriftAfterProjection, set.projectionTolerance);
  EXPECT_NEAR(momentum(s, last)[0], 4.0, kTol);
}

// Method 2 with growing stiffness k = EA/l0: the cable acts as a spring while taut, for
// pi sqrt(mu/k) (half a period of the reduced oscillator), stretching at most
// v_rel sqrt(mu/k), then releases the masses with their relative velocity reversed: an
// elastic bounce (velocities v1 = 8/3, v2 = 2/3), not method 1's plastic impact. What
// tends to method 1 as k grows is the path (the stretch and the contact time vanish),
// not the velocities after the snap: no impulse, the energy is stored and returned.
TEST(TensegritySnap, TwoMassMasslessElasticCableBouncesElastically) {
  const double mu = 2.0 / 3.0;
  for (double ea : {1e2, 1e4, 1e6}) {
    const TensegrityStructure s = twoMasses(false, ea);
    const double contact = M_PI * std::sqrt(mu / ea);
    MasslessCableSettings set;
    set.tEnd = 1.5 * contact;
    set.outputStep = contact / 50.0;
    set.cvode.rtol = 1e-10;
    set.cvode.atol = 1e-12;
    Recorder rec;
    const TensegrityRunSummary sum = MasslessCableIntegrator(s, set).run(rec.observer());
    ASSERT_TRUE(sum.ok) << sum.message;
    double maxStretch = 0.0;
    for (const auto& smp : rec.samples) maxStretch = std::max(maxStretch, smp.cableLength[0] - 1.0);
    const TensegrityEvent* slack = nullptr;
    for (const auto& e : rec.events) {
      if (e.type == TensegrityEvent::Type::Slack) slack = &e;
    }
    ASSERT_NE(slack, nullptr) << "EA = " << ea;
    // Switch time located by CVODE's root-finding: to the integration tolerance (1e-10
    // relative), checked at 1e-6 relative to leave room for the accumulated error.
    EXPECT_NEAR(slack->t, contact, 1e-6 * contact) << "EA = " << ea;
    // Stretch sampled every contact/50: within 1% of v_rel sqrt(mu/k) (cos(pi/50) > 0.998).
    EXPECT_NEAR(maxStretch, 2.0 * std::sqrt(mu / ea), 1e-2 * 2.0 * std::sqrt(mu / ea));
    const TensegritySample& last = rec.samples.back();
    EXPECT_NEAR(last.v[0], 8.0 / 3.0, 1e-6);
    EXPECT_NEAR(last.v[2], 2.0 / 3.0, 1e-6);
    EXPECT_NEAR(momentum(s, last)[0], 4.0, 1e-8);
    EXPECT_NEAR(sum.energyEnd, sum.energyStart, 1e-6 * sum.energyStart);
  }
}

namespace {

/// A planar chain of three masses and two cables, slack at the start, flying apart with
/// velocities chosen so that both cables snap (and the first again later).
TensegrityStructure chain(bool inextensible) {
  TensegrityStructure s(2);
  s.addNode("a", Eigen::Vector2d(0.0, 0.0), 1.0, {}, Eigen::Vector2d(-1.0, 0.3));
  s.addNode("b", Eigen::Vector2d(0.8, 0.1), 2.0, {}, Eigen::Vector2d(0.2, -0.4));
  s.addNode("c", Eigen::Vector2d(1.5, -0.2), 1.5, {}, Eigen::Vector2d(1.2, 0.5));
  s.addCable("ab", 0, 1, 1e4, 1.0, inextensible);
  s.addCable("bc", 1, 2, 1e4, 1.0, inextensible);
  s.finalize();
  return s;
}

}  // namespace

TEST(TensegritySnap, MomentumConservedAndEnergyNeverIncreasesAtSnapsMethod1) {
  const TensegrityStructure s = chain(true);
  TimeSteppingSettings set;
  set.tEnd = 3.0;
  set.timeStep = 1e-3;
  Recorder rec;
  const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run(rec.observer());
  ASSERT_TRUE(sum.ok) << sum.message;
  EXPECT_GE(sum.snaps, 2);
  const Eigen::VectorXd p0 = momentum(s, rec.samples.front());
  for (const auto& smp : rec.samples) {
    // Impulses are internal (equal and opposite) and the projection moves the nodes
    // along M^-1 B^T, which keeps the centre of mass: only round-off remains.
    EXPECT_NEAR((momentum(s, smp) - p0).norm(), 0.0, 1e-12);
  }
  // No forces: the energy changes only at snaps, and never increases (1e-12: round-off).
  for (const auto& e : rec.events) {
    if (e.type == TensegrityEvent::Type::Snap) EXPECT_LE(e.energyChange, 1e-12) << e.member << " t = " << e.t;
  }
  EXPECT_LE(sum.maxEnergyIncreaseAtSnap, 1e-12);
  for (std::size_t k = 1; k < rec.samples.size(); ++k) {
    EXPECT_LE(rec.samples[k].kineticEnergy, rec.samples[k - 1].kineticEnergy + 1e-12);
  }
  EXPECT_LT(sum.energyEnd, sum.energyStart);
}

TEST(TensegritySnap, MomentumAndEnergyConservedMethod2) {
  const TensegrityStructure s = chain(false);
  MasslessCableSettings set;
  set.tEnd = 3.0;
  set.outputStep = 0.01;
  set.cvode.rtol = 1e-10;
  set.cvode.atol = 1e-12;
  Recorder rec;
  const TensegrityRunSummary sum = MasslessCableIntegrator(s, set).run(rec.observer());
  ASSERT_TRUE(sum.ok) << sum.message;
  int taut = 0, slack = 0;
  for (const auto& e : rec.events) {
    taut += e.type == TensegrityEvent::Type::Taut;
    slack += e.type == TensegrityEvent::Type::Slack;
  }
  EXPECT_GE(taut, 2);
  EXPECT_GE(slack, 2);
  const Eigen::VectorXd p0 = momentum(s, rec.samples.front());
  const double e0 = rec.samples.front().kineticEnergy + rec.samples.front().potentialEnergy;
  for (const auto& smp : rec.samples) {
    // rtol 1e-10 over a few hundred steps: 1e-7 leaves a margin of ~100 over what we measure.
    EXPECT_NEAR((momentum(s, smp) - p0).norm(), 0.0, 1e-7);
    EXPECT_NEAR(smp.kineticEnergy + smp.potentialEnergy, e0, 1e-7 * e0);
  }
}
