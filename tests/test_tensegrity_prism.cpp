// The regular 3-strut tensegrity prism: self-stress from the equilibrium
// matrix against the analytic force densities, rest under prestress (both methods), and
// the release after shortening one cable (slack and taut events, energy history).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

#include "tensegrity/massless_cable_integrator.hpp"
#include "tensegrity/self_equilibrium.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;

namespace {

/// Bottom nodes b_i at angle 120 i deg (z = 0), top nodes t_i at 120 i + 150 deg (z = h),
/// radius 1. Struts b_i-t_i; bottom cables b_i-b_{i+1}; top cables t_i-t_{i+1};
/// vertical cables b_i-t_{i-1}. Members: struts 0-2, then cables: bottom 0-2, top
/// 3-5, vertical 6-8.
///
/// Analytic self-stress (equilibrium of node b_0, derived in docs/tensegrity.md): the
/// vertical cable and the strut at a node reach top nodes at angles gamma_c and gamma_s
/// from it, with sin gamma_c = sin gamma_s (tangential balance) => gamma_c = pi - gamma_s;
/// vertical balance q_v = -q_s; radial balance q_b = (2/3) q_s cos gamma_s. With
/// gamma_s = 150 deg: q_bottom : q_top : q_vertical : q_strut = 1 : 1 : sqrt 3 : -sqrt 3.
TensegrityStructure prism(bool inextensible, double ea = 1e4) {
  TensegrityStructure s(3);
  const double h = 1.5;
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0 * M_PI * i / 3.0;
    s.addNode("b" + std::to_string(i), Eigen::Vector3d(std::cos(a), std::sin(a), 0.0), 1.0, {},
              Eigen::Vector3d::Zero());
  }
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0 * M_PI * i / 3.0 + 150.0 * M_PI / 180.0;
    s.addNode("t" + std::to_string(i), Eigen::Vector3d(std::cos(a), std::sin(a), h), 1.0, {},
              Eigen::Vector3d::Zero());
  }
  const VecX x = s.initialPositions();
  auto len = [&](int i, int j) { return (x.segment<3>(3 * i) - x.segment<3>(3 * j)).norm(); };
  for (int i = 0; i < 3; ++i) s.addStrut("s" + std::to_string(i), i, 3 + i, 1e5, len(i, 3 + i), 0.0, BarMassModel::Lumped);
  for (int i = 0; i < 3; ++i) s.addCable("cb" + std::to_string(i), i, (i + 1) % 3, ea, len(i, (i + 1) % 3), inextensible);
  for (int i = 0; i < 3; ++i) {
    s.addCable("ct" + std::to_string(i), 3 + i, 3 + (i + 1) % 3, ea, len(3 + i, 3 + (i + 1) % 3), inextensible);
  }
  for (int i = 0; i < 3; ++i) {
    s.addCable("cv" + std::to_string(i), i, 3 + (i + 2) % 3, ea, len(i, 3 + (i + 2) % 3), inextensible);
  }
  s.finalize();
  return s;
}

/// Prestress with the computed self-stress, scaled so that q_bottom = 10 (tension 10 sqrt 3).
VecX prestress(TensegrityStructure& s) {
  const SelfStressStates st = computeSelfStress(s, s.initialPositions());
  VecX q = st.forceDensities.col(0);
  q /= q[3];  // member 3 = first bottom cable
  applyPrestress(s, q, 10.0);
  return q;
}

}  // namespace

TEST(TensegrityPrism, SelfStressMatchesAnalyticForceDensities) {
  TensegrityStructure s = prism(false);
  const SelfStressStates st = computeSelfStress(s, s.initialPositions());
  // One self-stress state; 18 coordinates - rank 11 = 7 mechanisms: the 6 rigid-body
  // motions and the prism's one infinitesimal mechanism (Pellegrino & Calladine).
  ASSERT_EQ(st.forceDensities.cols(), 1);
  EXPECT_EQ(st.rank, 11);
  EXPECT_EQ(st.mechanisms, 7);
  VecX q = st.forceDensities.col(0);
  q /= q[3];
  // Tolerance: the SVD is backward stable; 1e-12 is a few hundred ulps.
  constexpr double kTol = 1e-12;
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(q[j], -std::sqrt(3.0), kTol) << "strut " << j;
  for (int j = 3; j < 9; ++j) EXPECT_NEAR(q[j], 1.0, kTol) << "ring cable " << j;
  for (int j = 9; j < 12; ++j) EXPECT_NEAR(q[j], std::sqrt(3.0), kTol) << "vertical cable " << j;
  EXPECT_LT((equilibriumMatrix(s, s.initialPositions()) * q).norm(), kTol);
}

TEST(TensegrityPrism, PrestressedElasticPrismStaysAtRest) {
  TensegrityStructure s = prism(false);
  prestress(s);
  MasslessCableSettings set;
  set.tEnd = 2.0;
  set.outputStep = 0.1;
  double maxMove = 0.0;
  const VecX x0 = s.initialPositions();
  int events = 0;
  const TensegrityRunSummary sum = MasslessCableIntegrator(s, set).run(
      {[&](const TensegritySample& smp) { maxMove = std::max(maxMove, (smp.x - x0).lpNorm<Eigen::Infinity>()); },
       [&](const TensegrityEvent&) { ++events; }});
  ASSERT_TRUE(sum.ok) << sum.message;
  EXPECT_EQ(events, 0);
  // Equilibrium residual of the prestress is round-off (|A q| ~ 1e-15 with forces ~10):
  // the nodes stay within 1e-9 over 2 s.
  EXPECT_LT(maxMove, 1e-9);
}

TEST(TensegrityPrism, PrestressedInextensiblePrismStaysAtRest) {
  TensegrityStructure s = prism(true);
  prestress(s);
  TimeSteppingSettings set;
  set.tEnd = 1.0;
  set.timeStep = 1e-3;
  double maxMove = 0.0, maxTensionError = 0.0;
  const VecX x0 = s.initialPositions();
  int events = 0;
  const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run(
      {[&](const TensegritySample& smp) {
         maxMove = std::max(maxMove, (smp.x - x0).lpNorm<Eigen::Infinity>());
         if (smp.t > 0.0) {  // bottom cable: t = q l = 10 * sqrt(3) (side length sqrt 3)
           maxTensionError = std::max(maxTensionError, std::abs(smp.cableTension[0] - 10.0 * std::sqrt(3.0)));
         }
       },
       [&](const TensegrityEvent&) { ++events; }});
  ASSERT_TRUE(sum.ok) << sum.message;
  EXPECT_EQ(events, 0);
  EXPECT_LT(maxMove, 1e-9);
  // The LCP returns the prestress as the cable impulses / dt (Lemke: round-off only).
  EXPECT_LT(maxTensionError, 1e-8);
}

// Release: one vertical cable is shortened by 5 % at t = 0 (massless elastic cables,
// EA = 1e3). The prism jerks, some cables go slack and snap taut again.
TEST(TensegrityPrism, ReleaseAfterShorteningACableGivesSlackAndTautEvents) {
  TensegrityStructure s = prism(false, 1e3);
  prestress(s);
  s.setCableNaturalLength(6, 0.95 * s.cable(6).naturalLength);  // cable 6 = cv0
  MasslessCableSettings set;
  set.tEnd = 2.0;
  set.outputStep = 0.05;
  set.cvode.rtol = 1e-10;
  set.cvode.atol = 1e-12;
  std::vector<TensegrityEvent> events;
  std::vector<TensegritySample> samples;
  const TensegrityRunSummary sum = MasslessCableIntegrator(s, set).run(
      {[&](const TensegritySample& smp) { samples.push_back(smp); },
       [&](const TensegrityEvent& e) { events.push_back(e); }});
  ASSERT_TRUE(sum.ok) << sum.message;
  std::cout << "prism release: " << sum.slackTransitions << " slack and " << sum.tautTransitions
            << " taut events, first ones:";
  for (std::size_t k = 0; k < events.size() && k < 6; ++k) {
    std::cout << " " << toString(events[k].type) << " " << events[k].member << " t=" << events[k].t << ";";
  }
  std::cout << "\nenergy (t, kinetic, potential):";
  for (std::size_t k = 0; k < samples.size(); k += 8) {
    std::cout << " (" << samples[k].t << ", " << samples[k].kineticEnergy << ", " << samples[k].potentialEnergy << ")";
  }
  std::cout << std::endl;
  EXPECT_GE(sum.slackTransitions, 1);
  EXPECT_GE(sum.tautTransitions, 1);
  // No damping: the total energy is conserved through every switch (1e-7 relative,
  // rtol 1e-10 over some thousand steps).
  for (const auto& smp : samples) {
    EXPECT_NEAR(smp.kineticEnergy + smp.potentialEnergy, sum.energyStart, 1e-7 * std::abs(sum.energyStart));
  }
}
