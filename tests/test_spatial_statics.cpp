// Static equilibrium and modes at rest of spatial models: Newton in
// velocity space with Euler-parameter increments (analysis/static_equilibrium.hpp)
// against closed forms: a flexible L-frame under its weight, a rigid pendulum hanging
// from a revolute joint, and a clamped beam's bending frequencies about its sagged state.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "elements/beam_section.hpp"
#include "analysis/linearization.hpp"
#include "analysis/static_equilibrium.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

constexpr double g = 9.81;

/// Steel, square section 20 mm (Iy = Iz: the bending axes of the two legs need no care).
constexpr double kSide = 0.02, kE = 2.1e11, kNu = 0.3, kRho = 7850.0;

BeamSection3d steelSection() {
  return rectangularSection3d(kSide, kSide, kE, kE / (2.0 * (1.0 + kNu)), kRho, 0.0);
}

json sectionJson() {
  return {{"width", kSide}, {"height", kSide}, {"youngs_modulus", kE}, {"poisson_ratio", kNu}, {"density", kRho}};
}

/// A flat L-frame in the x-y plane, one flexible body: leg 1 from the origin along x
/// (length a, n elements), leg 2 from its end along y (length b, n elements); clamped at
/// node 0, welded there to the ground; gravity along -z, out of the frame's plane.
json lFrameScene(double a, double b, int n) {
  json nodes = json::array(), elements = json::array();
  for (int k = 0; k <= n; ++k) nodes.push_back({a * k / n, 0.0, 0.0});
  for (int k = 1; k <= n; ++k) nodes.push_back({a, b * k / n, 0.0});
  for (int k = 0; k < 2 * n; ++k) elements.push_back({k, k + 1});
  json body = {{"name", "frame"}, {"type", "flexible"}, {"section", sectionJson()}, {"nodes", nodes},
               {"elements", elements}, {"y_axis", {0, 0, 1}}, {"reference", {{"type", "clamped"}, {"node", 0}}}};
  return {{"name", "L-frame"},
          {"dimension", 3},
          {"gravity", {0, 0, -g}},
          {"bodies", {body}},
          {"joints", {{{"name", "root"}, {"type", "fixed"}, {"bodies", {"ground", "frame"}},
                       {"frames", {{{"point", {0, 0, 0}}}, {{"point", {0, 0, 0}}}}}}}},
          {"solver", {{"t_end", 1}}}};
}

const FfrBody3d& flexibleBody(const System& sys, const std::string& name) {
  return dynamic_cast<const FfrBody3d&>(sys.body(sys.findBody(name)));
}

/// The elastic coordinates q_f of a body in q (after its 3 position and 4 Euler parameters).
VecX elasticCoordinates(const System& sys, const std::string& name, const VecX& q) {
  const BodyIndex b = sys.findBody(name);
  return q.segment(sys.coordinateOffset(b) + 7, sys.body(b).numCoordinates() - 7);
}

/// max |Q - G^T lambda| (velocity space), evaluated independently of the solver.
double forceImbalance(const System& sys, const StaticEquilibrium& eq) {
  MatX G;
  VecX gq;
  evaluateConstraints(sys, eq.q, 0.0, &gq, &G);
  const VecX Q = generalizedForces(sys, 0.0, eq.q, VecX::Zero(sys.numVelocities()));
  return (Q - G.transpose() * eq.lambda).lpNorm<Eigen::Infinity>();
}

}  // namespace

TEST(SpatialStatics, FlexibleLFrameSagsByTheClosedFormOfBendingAndTorsion) {
  // Closed form (small deflections, Euler-Bernoulli bending, St Venant torsion; unit-load
  // superposition, e.g. Roark's Formulas for Stress and Strain, table 8.1 cases 1a and 2a,
  // and table 10.1 for torsion): w = rho A g per length on both legs,
  //   leg 1 is a cantilever under w plus, at its end, the force P = w b and the torque
  //   T = w b^2 / 2 about x from leg 2;
  //   corner deflection  d_c = w a^4 / (8 EI) + P a^3 / (3 EI),
  //   corner twist       phi = T a / (G J)  (the slope about y does not move leg 2),
  //   tip deflection     d_t = d_c + phi b + w b^4 / (8 EI).
  const double a = 1.0, b = 0.6;
  const BeamSection3d s = steelSection();
  const double w = s.massPerLength() * g, EI = s.bendingStiffnessY(), GJ = s.shearModulus * s.torsionConstant;
  const double P = w * b, T = w * b * b / 2;
  const double corner = w * std::pow(a, 4) / (8 * EI) + P * std::pow(a, 3) / (3 * EI);
  const double twist = T * a / GJ;
  const double tip = corner + twist * b + w * std::pow(b, 4) / (8 * EI);
  // Tolerance: the cubic Hermite element with consistent nodal loads (the FFR gravity
  // load is S-bar^T A^T g, the consistent one) is nodally exact for a uniformly loaded
  // Euler-Bernoulli beam (Tong 1969: the beam's Green's function is a piecewise cubic),
  // and the linear twist element is exact for torsion by nodal torques; with the frame
  // welded to the ground and no geometric stiffening the FFR statics are linear. So the
  // discretisation error at the nodes is zero and what remains is the round-off of a
  // solve with condition ~1e9 (measured 1e-14 and 4e-12 for 2 and 8 elements per leg); 1e-8
  // bounds it. Between the nodes the cubic does carry an O(h^4) error; only nodes are compared.
  constexpr double kNodallyExact = 1e-8;
  for (const int n : {2, 8}) {
    const Scene scene = parseScene(lFrameScene(a, b, n));
    const System& sys = scene.system;
    const StaticEquilibrium eq = solveStaticEquilibrium(sys, 0.0, sys.initialCoordinates());
    const FfrInvariants3d& inv = flexibleBody(sys, "frame").invariants();
    const VecX qf = elasticCoordinates(sys, "frame", eq.q);
    const Vec3 uCorner = inv.points[n].shape * qf, uTip = inv.points[2 * n].shape * qf;
    const Vec3 thetaCorner = inv.points[n].rotationShape * qf;
    EXPECT_NEAR(-uCorner.z() / corner, 1.0, kNodallyExact) << n << " elements per leg";
    EXPECT_NEAR(-thetaCorner.x() / twist, 1.0, kNodallyExact) << n << " elements per leg";
    EXPECT_NEAR(-uTip.z() / tip, 1.0, kNodallyExact) << n << " elements per leg";
    // the root carries the whole weight, w (a + b), and the frame has not moved
    const double weight = w * (a + b);
    EXPECT_LT(forceImbalance(sys, eq), 1e-9 * weight);
    EXPECT_LT(eq.constraintResidual, 1e-12);
    EXPECT_NEAR(eq.q.segment<3>(3).norm(), 1.0, 1e-15);  // Euler parameters stay unit
    std::printf("[ measured ] L-frame, %d elements per leg: tip %.9e m (closed form %.9e, rel. error %.2e), "
                "corner twist %.6e rad (%.2e), %d Newton iterations, %d increments\n",
                n, -uTip.z(), tip, -uTip.z() / tip - 1, -thetaCorner.x(), -thetaCorner.x() / twist - 1, eq.iterations,
                eq.increments);
  }
}

namespace {

/// A rigid arm (mass m, principal inertia (Ixx, Iyy, Izz) about its centre of mass) on a
/// revolute joint about the world y axis at the origin, its centre of mass a distance d
/// from the pivot (body point (0, 0, d) is the pivot); started at rest rotated by
/// `angle` about y, away from the bottom.
json spatialPendulum(double m, const Vec3& inertia, double d, double angle) {
  const Vec3 com(-d * std::sin(angle), 0.0, -d * std::cos(angle));  // pivot = com + R_y(angle) (0, 0, d) = 0
  return {{"name", "spatial pendulum"},
          {"dimension", 3},
          {"gravity", {0, 0, -g}},
          {"bodies", {{{"name", "arm"}, {"type", "rigid"}, {"mass", m}, {"inertia", {inertia.x(), inertia.y(), inertia.z()}},
                       {"position", {com.x(), com.y(), com.z()}},
                       {"orientation", {{"axis", {0, 1, 0}}, {"angle", angle}}}}}},
          {"joints", {{{"name", "pivot"}, {"type", "revolute"}, {"bodies", {"ground", "arm"}},
                       {"frames", {{{"point", {0, 0, 0}}, {"axis", {0, 1, 0}}}, {{"point", {0, 0, d}}, {"axis", {0, 1, 0}}}}}}}},
          {"solver", {{"t_end", 1}}}};
}

}  // namespace

TEST(SpatialStatics, RigidPendulumHangsAtTheBottomAndSwingsAtSqrtMgdOverIPivot) {
  const double m = 3.0, d = 0.35, angle = 1.2;  // 69 degrees from the bottom
  const Vec3 inertia(0.05, 0.08, 0.04);
  const Scene scene = parseScene(spatialPendulum(m, inertia, d, angle));
  const System& sys = scene.system;
  const StaticEquilibrium eq = solveStaticEquilibrium(sys, 0.0, sys.initialCoordinates());
  // Newton's tolerance is 1e-10 on the velocity-space correction relative to 1 + max |q|:
  // positions and angles to ~1e-10 (quadratic convergence leaves far less).
  constexpr double kNewtonTolerance = 1e-9;
  const Vec3 r = eq.q.head<3>();
  const Vec4 p = eq.q.segment<4>(3);
  EXPECT_NEAR(r.x(), 0.0, kNewtonTolerance);
  EXPECT_NEAR(r.y(), 0.0, kNewtonTolerance);
  EXPECT_NEAR(r.z(), -d, kNewtonTolerance);
  EXPECT_NEAR(p.norm(), 1.0, 1e-15);                      // unit Euler parameters
  EXPECT_NEAR(std::abs(p[0]), 1.0, kNewtonTolerance);     // back to the identity: no rotation left
  // the pivot holds the weight: the joint's force balances m g (|Q - G^T lambda| ~ 0)
  EXPECT_LT(forceImbalance(sys, eq), 1e-9 * m * g);
  EXPECT_GE(eq.iterations, 2);

  // small oscillations about it: omega^2 = m g d / (Iyy + m d^2) (compound pendulum, the
  // parallel-axis theorem). The linearisation at an equilibrium is exact up to rounding:
  // 1e-8 relative, as tests/test_linearization.cpp (kClosedFormTolerance).
  constexpr double kClosedFormTolerance = 1e-8;
  const ReferenceState ref = referenceStateAt(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  EXPECT_NEAR(ref.q[2], -d, kNewtonTolerance);  // the reference is the equilibrium, not the start
  const std::vector<Mode> modes = modesAbout(sys, ref);
  ASSERT_EQ(modes.size(), 1u);  // one degree of freedom
  const double exact = std::sqrt(m * g * d / (inertia.y() + m * d * d));
  EXPECT_NEAR(modes[0].omega / exact - 1.0, 0.0, kClosedFormTolerance);
  EXPECT_NEAR(modes[0].dampingRatio, 0.0, kClosedFormTolerance);
  std::printf("[ measured ] spatial pendulum from %.2f rad: rest at z = %.12f (d = %.2f), %d Newton iterations, "
              "%d increments; omega %.12f rad/s vs %.12f (rel. error %.2e)\n",
              angle, r.z(), d, eq.iterations, eq.increments, modes[0].omega, exact, modes[0].omega / exact - 1);
}

TEST(SpatialStatics, ClampedBeamSaggedUnderGravityHasTheEulerBernoulliFrequencies) {
  // A steel cantilever along x (clamped node 0 welded to the ground), its weight along -z:
  // the modes at rest are taken about the static equilibrium (the sag), then compared with
  // omega_1 = (beta_1 L)^2 sqrt(EI / (rho A L^4)), beta_1 L = 1.87510407 (Euler-Bernoulli
  // clamped-free; Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1). Square
  // section: the two bending planes share omega_1. The FFR model without stiffening is
  // linear, so the sag does not shift the frequencies.
  const double L = 1.2;
  const int n = 8;
  json j = {{"name", "cantilever"},
            {"dimension", 3},
            {"gravity", {0, 0, -g}},
            {"bodies", {{{"name", "beam"}, {"type", "flexible"}, {"section", sectionJson()},
                         {"beam", {{"length", L}, {"elements", n}}}, {"reference", {{"type", "clamped"}}}}}},
            {"joints", {{{"name", "root"}, {"type", "fixed"}, {"bodies", {"ground", "beam"}},
                         {"frames", {{{"point", {0, 0, 0}}}, {{"point", {0, 0, 0}}}}}}}},
            {"solver", {{"t_end", 1}}}};
  const Scene scene = parseScene(j);
  const System& sys = scene.system;
  const ReferenceState ref = referenceStateAt(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const BeamSection3d s = steelSection();
  const double EI = s.bendingStiffnessY(), rhoA = s.massPerLength();
  // the reference is the sagged equilibrium: tip deflection w L^4 / (8 EI), nodally exact
  // (consistent loads, see the L-frame test; 1e-8: round-off)
  const VecX qf = elasticCoordinates(sys, "beam", ref.q);
  const double tip = -(flexibleBody(sys, "beam").invariants().points.back().shape * qf).z();
  const double sag = rhoA * g * std::pow(L, 4) / (8 * EI);
  EXPECT_NEAR(tip / sag, 1.0, 1e-8);
  EXPECT_EQ(ref.a.lpNorm<Eigen::Infinity>(), 0.0);
  ModesOptions o;
  o.count = 4;
  const std::vector<Mode> modes = modesAbout(sys, ref, o);
  ASSERT_GE(modes.size(), 3u);
  constexpr double kBeta1L = 1.87510407;
  const double exact = kBeta1L * kBeta1L * std::sqrt(EI / (rhoA * std::pow(L, 4)));
  // Discretisation: cubic elements converge as h^4 in frequency; 8 elements give ~1e-6
  // relative for the first bending mode (measured 2.1e-6); 1e-5 bounds it.
  constexpr double kEightElementError = 1e-5;
  EXPECT_NEAR(modes[0].omega / exact, 1.0, kEightElementError);
  EXPECT_NEAR(modes[1].omega / exact, 1.0, kEightElementError);
  // both modes are the beam model's own (the same K_ff, m_ff: 1e-9)
  const VecX w = flexibleBody(sys, "beam").model()->naturalFrequencies();
  EXPECT_NEAR(modes[0].omega, w[0], 1e-9 * w[0]);
  EXPECT_NEAR(modes[2].omega, w[2], 1e-9 * w[2]);
  std::printf("[ measured ] sagged cantilever: tip %.6e m (closed form %.6e, rel. error %.2e); omega_1 %.9f, %.9f "
              "rad/s vs Euler-Bernoulli %.9f (rel. errors %.2e, %.2e)\n",
              tip, sag, tip / sag - 1, modes[0].omega, modes[1].omega, exact, modes[0].omega / exact - 1, modes[1].omega / exact - 1);
}

TEST(SpatialStatics, RedundantConstraintsAreSolvedWhenReleased) {
  // Two identical revolute joints on the pendulum: five of the second one's equations repeat
  // the first's. Kept, they make the tangent singular (a ModelError that says so);
  // released (as the run's "resolve" finds them), the equilibrium is the single joint's.
  json j = spatialPendulum(2.0, Vec3(0.01, 0.02, 0.01), 0.3, 0.7);
  j["joints"].push_back(j["joints"][0]);
  j["joints"][1]["name"] = "again";
  const Scene scene = parseScene(j);
  const System& sys = scene.system;
  try {
    solveStaticEquilibrium(sys, 0.0, sys.initialCoordinates());
    FAIL() << "expected a ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("redundant constraints"), std::string::npos) << e.what();
  }
  StaticEquilibriumOptions o;
  o.released = {5, 6, 7, 8, 9};
  const StaticEquilibrium eq = solveStaticEquilibrium(sys, 0.0, sys.initialCoordinates(), o);
  EXPECT_NEAR(eq.q[2], -0.3, 1e-9);
  for (int k = 5; k < 10; ++k) EXPECT_EQ(eq.lambda[k], 0.0);
  // modes at rest release what the consistent initialisation releases (detect, as a run's
  // "resolve"): the equilibrium and the frequency are the single joint's (1e-8, as above)
  ReleasedEquations detect;
  detect.detect = true;
  const ReferenceState ref = referenceStateAt(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities(), detect);
  EXPECT_NEAR(ref.q[2], -0.3, 1e-9);
  const std::vector<Mode> modes = modesAbout(sys, ref);
  ASSERT_EQ(modes.size(), 1u);
  const double exact = std::sqrt(2.0 * g * 0.3 / (0.02 + 2.0 * 0.3 * 0.3));
  EXPECT_NEAR(modes[0].omega / exact, 1.0, 1e-8);
  EXPECT_NEAR(modes[0].dampingRatio, 0.0, 1e-8);  // an oscillation: the stable (bottom) equilibrium
}

TEST(SpatialStatics, StiffenedCantileverTurnedInSpaceNeedsLoadSteppingAndKeepsTheLinearTipDeflection) {
  // The planar load-stepping case of tests/test_static_equilibrium.cpp in space: a steel
  // cantilever (L = 1 m, 8 elements, geometric stiffening) welded to the ground with its
  // frame turned 0.7 rad about (1, 1, 1) (every Euler parameter non-zero), a dead tip load
  // P along the body's -z axis (given in world axes) deflecting it 20 % of L linearly.
  // The element-averaged membrane strain and the free axial end make the membrane force
  // zero in every element, so this moderate-rotation model's answer is the linear
  // P L^3 / (3 E I), to which Hermite elements are nodally exact (docs/flexible-bodies.md,
  // "Geometric stiffening"). Tolerance as the planar test's: the Newton tolerance (1e-10
  // relative change of q) times the tangent's conditioning, 1e-7.
  constexpr double kModelExact = 1e-7;
  const double L = 1.0, fraction = 0.2;
  const BeamSection3d s = steelSection();
  const double EI = s.bendingStiffnessY(), P = fraction * L * 3 * EI / std::pow(L, 3);
  const Eigen::AngleAxisd turn(0.7, Vec3(1, 1, 1).normalized());
  const Vec3 force = -P * (turn.toRotationMatrix() * Vec3::UnitZ());
  const json orientation = {{"axis", {1, 1, 1}}, {"angle", 0.7}};
  const auto law = [](double value) { return json{{"type", "constant"}, {"value", value}}; };
  const json j = {
      {"name", "stiffened cantilever"},
      {"dimension", 3},
      {"gravity", {0, 0, 0}},
      {"bodies", {{{"name", "beam"}, {"type", "flexible"}, {"section", sectionJson()}, {"orientation", orientation},
                   {"beam", {{"length", L}, {"elements", 8}}}, {"reference", {{"type", "clamped"}}},
                   {"geometric_stiffening", true}}}},
      {"joints", {{{"name", "root"}, {"type", "fixed"}, {"bodies", {"ground", "beam"}},
                   {"frames", {{{"point", {0, 0, 0}}, {"orientation", orientation}}, {{"point", {0, 0, 0}}}}}}}},
      {"forces", {{{"name", "tip"}, {"type", "applied_load"}, {"body", "beam"}, {"point", {L, 0, 0}},
                   {"force_x", law(force.x())}, {"force_y", law(force.y())}, {"force_z", law(force.z())}}}},
      {"solver", {{"t_end", 1}}}};
  const Scene scene = parseScene(j);
  const System& sys = scene.system;
  const StaticEquilibrium eq = solveStaticEquilibrium(sys, 0.0, sys.initialCoordinates());
  EXPECT_GT(eq.increments, 1);  // Newton alone does not take the whole load (as in the plane)
  const VecX qf = elasticCoordinates(sys, "beam", eq.q);
  const Vec3 tip = flexibleBody(sys, "beam").invariants().points.back().shape * qf;  // body axes
  EXPECT_NEAR(-tip.z() / (fraction * L), 1.0, kModelExact);
  EXPECT_NEAR(tip.y(), 0.0, kModelExact * fraction * L);
  // the frame has not moved: the welded Euler parameters are the turn's
  const Eigen::Quaterniond p0(turn);
  const Vec4 p = eq.q.segment<4>(3);
  EXPECT_NEAR(std::abs(p0.w() * p[0] + p0.x() * p[1] + p0.y() * p[2] + p0.z() * p[3]), 1.0, 1e-12);
  EXPECT_LT(forceImbalance(sys, eq), 1e-9 * P);
  std::printf("[ measured ] spatial stiffened cantilever at %.0f %% of L: tip %.9f m (%.2e from linear), %d Newton "
              "iterations, %d load increments\n",
              100 * fraction, -tip.z(), -tip.z() / (fraction * L) - 1, eq.iterations, eq.increments);
}
