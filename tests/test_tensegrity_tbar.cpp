// Planar T-bar tensegrity: two crossed struts (they pass over each other out
// of plane: no contact is checked), four perimeter cables, left node pinned, right node
// on a vertical roller, a horizontal load ramped at the top node. Method 1 (inextensible
// cables) against method 2 (massless elastic cables, stiffness growing).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

#include "tensegrity/massless_cable_integrator.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;

namespace {

TensegrityStructure tbar(bool inextensible, double cableEa) {
  TensegrityStructure s(2);
  s.addNode("left", Eigen::Vector2d(-1, 0), 1.0, {true, true}, Eigen::Vector2d::Zero());
  s.addNode("right", Eigen::Vector2d(1, 0), 1.0, {false, true}, Eigen::Vector2d::Zero());
  s.addNode("top", Eigen::Vector2d(0, 1), 1.0, {}, Eigen::Vector2d::Zero());
  s.addNode("bottom", Eigen::Vector2d(0, -1), 1.0, {}, Eigen::Vector2d::Zero());
  s.addStrut("horizontal", 0, 1, 1e3, 2.0, 0.0, BarMassModel::Lumped);
  s.addStrut("vertical", 2, 3, 1e3, 2.0, 0.0, BarMassModel::Lumped);
  const double l = std::sqrt(2.0);
  s.addCable("left_top", 0, 2, cableEa, l, inextensible);
  s.addCable("top_right", 2, 1, cableEa, l, inextensible);
  s.addCable("right_bottom", 1, 3, cableEa, l, inextensible);
  s.addCable("bottom_left", 3, 0, cableEa, l, inextensible);
  // Horizontal load at the top node ramped 0 -> 10 over 0.5 s, then held.
  s.addLoad("push", 2, {makeTabulatedLaw({0.0, 0.5, 5.0}, {0.0, 10.0, 10.0}), nullptr});
  s.finalize();
  return s;
}

}  // namespace

TEST(TensegrityTBar, Method1AndMethod2AgreeAsCablesStiffen) {
  const double tEnd = 1.0, out = 0.01;
  TimeSteppingSettings s1;
  s1.tEnd = tEnd;
  s1.timeStep = 1e-4;
  s1.outputStep = out;
  std::vector<TensegritySample> m1;
  const TensegrityStructure t1 = tbar(true, 0.0);
  int slack1 = 0;
  const TensegrityRunSummary r1 = TensegrityTimeStepper(t1, s1).run(
      {[&](const TensegritySample& smp) { m1.push_back(smp); },
       [&](const TensegrityEvent& e) { slack1 += e.type == TensegrityEvent::Type::Slack; }});
  ASSERT_TRUE(r1.ok) << r1.message;
  EXPECT_GE(slack1, 1);  // the load slackens the cables it pushes towards
  double previous = 1e300;
  for (double ea : {1e4, 1e5, 1e6}) {
    MasslessCableSettings s2;
    s2.tEnd = tEnd;
    s2.outputStep = out;
    s2.cvode.rtol = 1e-9;
    s2.cvode.atol = 1e-11;
    std::vector<TensegritySample> m2;
    const TensegrityStructure t2 = tbar(false, ea);
    const TensegrityRunSummary r2 =
        MasslessCableIntegrator(t2, s2).run({[&](const TensegritySample& smp) { m2.push_back(smp); }, nullptr});
    ASSERT_TRUE(r2.ok) << r2.message;
    ASSERT_EQ(m1.size(), m2.size());
    double diff = 0.0;
    for (std::size_t k = 0; k < m1.size(); ++k) diff = std::max(diff, (m1[k].x - m2[k].x).lpNorm<Eigen::Infinity>());
    std::cout << "T-bar: cable EA = " << ea << ": max |x1 - x2| = " << diff << " (top node x at t = 1: method 1 "
              << m1.back().x[4] << ", method 2 " << m2.back().x[4] << "; " << r2.slackTransitions << " slack, "
              << r2.tautTransitions << " taut switches, " << r2.steps << " CVODE steps)" << std::endl;
    EXPECT_LT(diff, previous);  // converging as the cables stiffen
    previous = diff;
  }
  // With EA = 1e6 the cables stretch by ~ tension/EA ~ 1e-5 and the time-stepper's error
  // is O(dt) = 1e-4: the two agree to 1e-3 in position.
  EXPECT_LT(previous, 1e-3);
}
