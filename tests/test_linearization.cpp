// Linearisation and modal analysis (analysis/linearization.hpp, docs/modes.md):
// small oscillations and gyroscopic stability against closed forms, planar and spatial.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"
#include "analysis/linearization.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

constexpr double g = 9.81;

/// The linearisation of an equilibrium or steady motion is exact up to rounding: the
/// frequencies of rigid models agree with their closed forms to this relative error
/// (eigenvalues of a matrix of condition ~1e3 in double precision).
constexpr double kClosedFormTolerance = 1e-8;

/// computed, exact and their relative error in the test's XML record (--gtest_output=xml).
void record(const std::string& name, double computed, double exact) {
  char buf[120];
  std::snprintf(buf, sizeof buf, "%.12g vs %.12g (rel. error %.2e)", computed, exact, computed / exact - 1);
  ::testing::Test::RecordProperty(name, buf);
}

ReferenceState initialReference(const System& sys) {
  return referenceStateAt(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
}

std::vector<Mode> modesOf(const json& scene, int count, EigenSolverKind solver = EigenSolverKind::Automatic,
                          BasisKind basis = BasisKind::Svd) {
  const Scene s = parseScene(scene);
  ModesOptions o;
  o.count = count;
  o.solver = solver;
  return modesAbout(s.system, initialReference(s.system), o, basis);
}

/// Elastic (non-zero) modes only.
std::vector<Mode> nonZero(const std::vector<Mode>& modes) {
  std::vector<Mode> out;
  for (const Mode& m : modes) {
    if (m.omega > 0.0) out.push_back(m);
  }
  return out;
}

/// A uniform rod (mass m, length L) hanging from a revolute joint at the origin.
json planarRodPendulum(double m, double L) {
  return json::parse(R"({"name": "rod pendulum", "gravity": [0, -9.81],
    "bodies": [{"name": "rod", "type": "rigid", "mass": 1, "inertia": 1, "com": [0, 0], "angle": -1.5707963267948966}],
    "joints": [{"name": "O", "type": "revolute", "bodies": ["ground", "rod"], "points": [[0, 0], [0, 0]]}],
    "solver": {"t_end": 1}})")
      .patch(json::array({{{"op", "replace"}, {"path", "/bodies/0/mass"}, {"value", m}},
                          {{"op", "replace"}, {"path", "/bodies/0/inertia"}, {"value", m * L * L / 12}},
                          {{"op", "replace"}, {"path", "/bodies/0/com"}, {"value", {L / 2, 0.0}}}}));
}

}  // namespace

TEST(Linearization, PlanarRodPendulumSwingsAtTheCompoundPendulumFrequency) {
  const double m = 2.0, L = 0.8;
  const std::vector<Mode> modes = modesOf(planarRodPendulum(m, L), 5);
  ASSERT_EQ(modes.size(), 1u);  // one degree of freedom
  // compound pendulum: omega^2 = m g (L/2) / (m L^2 / 3)
  const double exact = std::sqrt(3 * g / (2 * L));
  record("omega", modes[0].omega, exact);
  EXPECT_NEAR(modes[0].omega / exact - 1, 0.0, kClosedFormTolerance);
  EXPECT_NEAR(modes[0].eigenvalue.real(), 0.0, kClosedFormTolerance * exact);
  EXPECT_NEAR(modes[0].frequencyHz, exact / (2 * M_PI), kClosedFormTolerance * exact);
  EXPECT_NEAR(modes[0].dampingRatio, 0.0, kClosedFormTolerance);
  // the shape is the rotation of the rod about the pivot: theta_dot 1, x_dot = L/2 (com at (0, -L/2))
  const Scene s = parseScene(planarRodPendulum(m, L));
  ASSERT_EQ(modes[0].shape.size(), s.system.numVelocities());
}

TEST(Linearization, SpatialRodOnASphericalJointSwingsAtTheSameFrequencyInTwoPlanes) {
  const double m = 2.0, L = 0.8;
  const json scene = json::parse(R"({"name": "spatial rod pendulum", "dimension": 3, "gravity": [0, 0, -9.81],
    "bodies": [{"name": "rod", "type": "rigid", "mass": 2.0, "inertia": [0.10666666666666667, 0.10666666666666667, 0.001],
                "position": [0, 0, -0.4]}],
    "joints": [{"name": "S", "type": "spherical", "bodies": ["ground", "rod"],
                "frames": [{"point": [0, 0, 0]}, {"point": [0, 0, 0.4]}]}],
    "solver": {"t_end": 1}})");
  ASSERT_NEAR(0.10666666666666667, m * L * L / 12, 1e-15);
  const std::vector<Mode> modes = modesOf(scene, 5);
  // three degrees of freedom: the spin about the rod's axis (zero) and two swings
  ASSERT_EQ(modes.size(), 3u);
  EXPECT_EQ(modes[0].omega, 0.0);
  const double exact = std::sqrt(3 * g / (2 * L));
  record("omega_swing_1", modes[1].omega, exact);
  record("omega_swing_2", modes[2].omega, exact);
  EXPECT_NEAR(modes[1].omega / exact - 1, 0.0, kClosedFormTolerance);
  EXPECT_NEAR(modes[2].omega / exact - 1, 0.0, kClosedFormTolerance);
}

TEST(Linearization, ParallelogramFourBarHangingUnderGravityAgainstItsOneDegreeOfFreedomClosedForm) {
  // crank and rocker (length a, mass m1, com at a/2, inertia I1 about it) hang from
  // pivots d apart; the coupler (mass m2) translates: kinetic energy
  // 1/2 (2 J1 + m2 a^2) phi'^2 with J1 = I1 + m1 (a/2)^2, potential
  // -(2 m1 g a/2 + m2 g a) cos phi: omega^2 = g (m1 a + m2 a) / (2 J1 + m2 a^2).
  const double a = 0.5, d = 1.2, m1 = 1.0, I1 = 0.03, m2 = 3.0, I2 = 0.4;
  json scene = {
      {"name", "parallelogram"},
      {"gravity", {0, -g}},
      {"bodies",
       {{{"name", "crank"}, {"type", "rigid"}, {"mass", m1}, {"inertia", I1}, {"com", {a / 2, 0}}, {"angle", -M_PI / 2}},
        {{"name", "coupler"}, {"type", "rigid"}, {"mass", m2}, {"inertia", I2}, {"com", {d / 2, 0}},
         {"position", {0, -a}}},
        {{"name", "rocker"}, {"type", "rigid"}, {"mass", m1}, {"inertia", I1}, {"com", {a / 2, 0}},
         {"position", {d, 0}}, {"angle", -M_PI / 2}}}},
      {"joints",
       {{{"name", "O1"}, {"type", "revolute"}, {"bodies", {"ground", "crank"}}, {"points", {{0, 0}, {0, 0}}}},
        {{"name", "O2"}, {"type", "revolute"}, {"bodies", {"crank", "coupler"}}, {"points", {{a, 0}, {0, 0}}}},
        {{"name", "O3"}, {"type", "revolute"}, {"bodies", {"coupler", "rocker"}}, {"points", {{d, 0}, {a, 0}}}},
        {{"name", "O4"}, {"type", "revolute"}, {"bodies", {"ground", "rocker"}}, {"points", {{d, 0}, {0, 0}}}}}},
      {"solver", {{"t_end", 1}}}};
  const std::vector<Mode> modes = modesOf(scene, 5);
  ASSERT_EQ(modes.size(), 1u);
  const double J1 = I1 + m1 * a * a / 4;
  const double exact = std::sqrt(g * (m1 * a + m2 * a) / (2 * J1 + m2 * a * a));
  record("omega", modes[0].omega, exact);
  EXPECT_NEAR(modes[0].omega / exact - 1, 0.0, kClosedFormTolerance);
  // the coupling basis gives the same frequency
  const std::vector<Mode> cp = modesOf(scene, 5, EigenSolverKind::Dense, BasisKind::CoordinatePartitioning);
  ASSERT_EQ(cp.size(), 1u);
  EXPECT_NEAR(cp[0].omega / exact - 1, 0.0, kClosedFormTolerance);
}

namespace {

constexpr double kBeamLength = 1.2, kE = 2e11, kRho = 7800, kWidth = 0.02, kHeight = 0.01;

json freeFreeBeam(int elements) {
  return {{"name", "free-free beam"},
          {"bodies",
           {{{"name", "beam"},
             {"type", "flexible"},
             {"section", {{"width", kWidth}, {"height", kHeight}, {"youngs_modulus", kE}, {"density", kRho}}},
             {"beam", {{"length", kBeamLength}, {"elements", elements}}},
             {"reference", {{"type", "free_free"}}}}}},
          {"solver", {{"t_end", 1}}}};
}

}  // namespace

TEST(Linearization, FreeFreeBeamHasThreeRigidModesAndTheModelsElasticFrequencies) {
  const json scene = freeFreeBeam(12);
  const Scene s = parseScene(scene);
  const auto& body = dynamic_cast<const FfrBody2d&>(s.system.body(s.system.findBody("beam")));
  const VecX model = body.beamModel()->naturalFrequencies();
  const std::vector<Mode> modes = modesOf(scene, 6);
  ASSERT_EQ(modes.size(), 6u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(modes[k].omega, 0.0) << "rigid mode " << k;
  // mean-axis conditions make the elastic modes orthogonal to the rigid ones: the free
  // body's frequencies are those of the body on its fixed frame, to rounding (the ratio
  // of the highest to the lowest frequency of 12 elements is ~1e4: eigenvalue errors
  // ~1e-12 relative to the largest)
  constexpr double kModelTolerance = 1e-7;
  for (int k = 0; k < 3; ++k) {
    record("omega_elastic_" + std::to_string(k + 1), modes[3 + k].omega, model[k]);
    EXPECT_NEAR(modes[3 + k].omega / model[k] - 1, 0.0, kModelTolerance) << k;
  }
  // continuum (Euler-Bernoulli, free-free): omega_1 = 22.373 / L^2 sqrt(EI / (rho A));
  // 12 cubic elements: discretisation error ~1e-5, the constant's 5 digits ~2e-5
  constexpr double kContinuumTolerance = 1e-4;
  const double A = kWidth * kHeight, I = kWidth * kHeight * kHeight * kHeight / 12;
  const double continuum = 22.373 / (kBeamLength * kBeamLength) * std::sqrt(kE * I / (kRho * A));
  record("omega_1_continuum", modes[3].omega, continuum);
  EXPECT_NEAR(modes[3].omega / continuum - 1, 0.0, kContinuumTolerance);
}

TEST(Linearization, DenseAndSparseSolversAgreeOnAFlexiblePendulum) {
  // a 40-element beam hanging from a revolute joint at its clamped end, under gravity:
  // 121 independent coordinates; geometric stiffness of gravity included
  json scene = {{"name", "flexible pendulum"},
                {"gravity", {0, -g}},
                {"bodies",
                 {{{"name", "beam"},
                   {"type", "flexible"},
                   {"angle", -M_PI / 2},
                   {"section", {{"width", kWidth}, {"height", kHeight}, {"youngs_modulus", kE}, {"density", kRho}}},
                   {"beam", {{"length", kBeamLength}, {"elements", 40}}},
                   {"reference", {{"type", "clamped"}}}}}},
                {"joints",
                 {{{"name", "O"}, {"type", "revolute"}, {"bodies", {"ground", "beam"}}, {"points", {{0, 0}, {0, 0}}}}}},
                {"solver", {{"t_end", 1}}}};
  const std::vector<Mode> dense = modesOf(scene, 6, EigenSolverKind::Dense);
  const std::vector<Mode> sparse = modesOf(scene, 6, EigenSolverKind::Sparse, BasisKind::CoordinatePartitioning);
  ASSERT_EQ(dense.size(), 6u);
  ASSERT_EQ(sparse.size(), 6u);
  // the same eigenvalues by two algorithms and two bases: agreement to the dense solver's
  // rounding relative to the largest eigenvalue of the 242 x 242 first-order matrix
  // (~1e-16 x 1e6 rad/s against 3.5 rad/s; measured 2e-9)
  constexpr double kSolverAgreement = 1e-7;
  for (int k = 0; k < 6; ++k) {
    record("omega_" + std::to_string(k + 1) + "_sparse_vs_dense", sparse[k].omega, dense[k].omega);
    EXPECT_NEAR(sparse[k].omega / dense[k].omega - 1, 0.0, kSolverAgreement) << k;
    // the shapes agree up to sign (both scaled to a largest entry of 1)
    const double diff = std::min((sparse[k].shape - dense[k].shape).norm(), (sparse[k].shape + dense[k].shape).norm());
    EXPECT_LT(diff, 1e-4 * dense[k].shape.norm()) << k;
  }
  // the rigid pendulum mode comes first, near sqrt(3 g / (2 L)) (the beam is stiff)
  EXPECT_NEAR(dense[0].omega / std::sqrt(3 * g / (2 * kBeamLength)) - 1, 0.0, 1e-3);
}

namespace {

/// A free rigid body with principal moments (2, 3, 4) spinning at w0 about body axis `axis`.
json spinningBody(int axis, double w0) {
  json omega = {0.0, 0.0, 0.0};
  omega[axis] = w0;
  return {{"name", "spinning body"},
          {"dimension", 3},
          {"bodies",
           {{{"name", "top"}, {"type", "rigid"}, {"mass", 1.5}, {"inertia", {2.0, 3.0, 4.0}},
             {"angular_velocity", omega}}}},
          {"solver", {{"t_end", 1}}}};
}

double largestGrowthRate(const std::vector<Mode>& modes) {
  double r = -1e300;
  for (const Mode& m : modes) r = std::max(r, m.eigenvalue.real());
  return r;
}

}  // namespace

TEST(Linearization, TorqueFreeSpinAboutTheIntermediateAxisGrowsAtTheEulerRate) {
  const double w0 = 3.0, I1 = 2, I2 = 3, I3 = 4;
  const std::vector<Mode> modes = modesOf(spinningBody(1, w0), 12);
  // Euler's equations linearised about w = w0 e2: s^2 = w0^2 (I3 - I2)(I2 - I1) / (I1 I3)
  const double growth = w0 * std::sqrt((I3 - I2) * (I2 - I1) / (I1 * I3));
  record("growth_rate", largestGrowthRate(modes), growth);
  EXPECT_NEAR(largestGrowthRate(modes) / growth - 1, 0.0, kClosedFormTolerance);
}

TEST(Linearization, TorqueFreeSpinAboutTheMajorAxisIsStableWithTheNutationFrequency) {
  const double w0 = 3.0, I1 = 2, I2 = 3, I3 = 4;
  const std::vector<Mode> modes = modesOf(spinningBody(2, w0), 12);
  EXPECT_LT(largestGrowthRate(modes), kClosedFormTolerance * w0);
  // nutation (Euler): w0 sqrt((I3 - I1)(I3 - I2) / (I1 I2)); and the attitude of the
  // spinning body seen from its body axes turns at w0 (the kinematic term B)
  const double nutation = w0 * std::sqrt((I3 - I1) * (I3 - I2) / (I1 * I2));
  bool foundNutation = false, foundSpin = false;
  for (const Mode& m : nonZero(modes)) {
    if (std::abs(m.omega / nutation - 1) < 1e-3) record("omega_nutation", m.omega, nutation);
    foundNutation = foundNutation || std::abs(m.omega / nutation - 1) < kClosedFormTolerance;
    foundSpin = foundSpin || std::abs(m.omega / w0 - 1) < kClosedFormTolerance;
  }
  EXPECT_TRUE(foundNutation);
  EXPECT_TRUE(foundSpin);
}

TEST(Linearization, RejectsAStateOfTheWrongSize) {
  const Scene s = parseScene(planarRodPendulum(1, 1));
  ReferenceState r = initialReference(s.system);
  r.v.resize(1);
  EXPECT_THROW(linearize(s.system, r), InputError);
}

// A sparse eigensolver that cannot do its work is a SolverError (the command
// line's exit 1), not an InputError or ModelError (exit 2, bad input): the model is well
// formed and the dense solver finds its modes. Forced by a shift at an eigenvalue: four
// free planar bodies have only s = 0, and a shift of 0 makes the shifted pencil singular.
TEST(Linearization, ASparseSolverFailureIsASolverErrorNotBadInput) {
  json scene = {{"name", "free bodies"}, {"bodies", json::array()}, {"solver", {{"t_end", 1}}}};
  for (int i = 0; i < 4; ++i) {
    scene["bodies"].push_back({{"name", "b" + std::to_string(i)}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", 0.1},
                               {"position", {1.0 * i, 0.0}}});
  }
  const Scene s = parseScene(scene);
  ModesOptions o;
  o.count = 2;
  o.solver = EigenSolverKind::Sparse;
  o.shift = 0.0;
  try {
    modesAbout(s.system, initialReference(s.system), o, BasisKind::CoordinatePartitioning);
    ADD_FAILURE() << "no exception";
  } catch (const SolverError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("sparse eigensolver"), std::string::npos) << m;
    EXPECT_NE(m.find("dense"), std::string::npos) << m;  // the way out
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a SolverError: " << e.what();
  }
  o.solver = EigenSolverKind::Dense;  // the same model: 12 free coordinates, s = 0 only
  const std::vector<Mode> modes = modesAbout(s.system, initialReference(s.system), o);
  ASSERT_EQ(modes.size(), 2u);
  for (const Mode& m : modes) EXPECT_EQ(m.omega, 0.0);
}

TEST(Linearization, RotatingBladeStiffensWithTheSouthwellCoefficientAboutItsSteadyStretchedState) {
  // a uniform cantilever blade (clamped at the hub, no hub radius) turned in its plane at
  // Omega: in-plane bending omega^2 = omega_0^2 + (K1 - 1) Omega^2, Southwell coefficient
  // K1 = 1.1933 (first mode; Wright, Smith, Thresher & Wang, J. Appl. Mech. 49 (1982)
  // 197-202). It needs the centrifugal stretch (solveSteadyMotion) and the second-order
  // axial strain (geometric_stiffening).
  const auto blade = [](double speed) {
    return json{{"name", "blade"},
                {"bodies",
                 {{{"name", "blade"},
                   {"type", "flexible"},
                   {"geometric_stiffening", true},
                   {"section", {{"width", kWidth}, {"height", kHeight}, {"youngs_modulus", kE}, {"density", kRho}}},
                   {"beam", {{"length", 1.0}, {"elements", 16}}},
                   {"reference", {{"type", "clamped"}}}}}},
                {"joints",
                 {{{"name", "hub"}, {"type", "revolute"}, {"bodies", {"ground", "blade"}}, {"points", {{0, 0}, {0, 0}}}}}},
                {"drivers",
                 {{{"name", "motor"}, {"type", "joint_angle"}, {"joint", "hub"},
                   {"law", {{"type", "constant_speed"}, {"speed", speed}}}}}},
                {"solver", {{"t_end", 1}}}};
  };
  const auto firstMode = [&](double speed) {
    const Scene s = parseScene(blade(speed));
    const System& sys = s.system;
    const ReferenceState ref = solveSteadyMotion(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
    EXPECT_LT(ref.a.lpNorm<Eigen::Infinity>(), 1e-6) << "the motion is steady";
    ModesOptions o;
    o.count = 1;
    return modesAbout(sys, ref, o).at(0).omega;
  };
  const double Omega = 10.0, w0 = firstMode(0.0), w = firstMode(Omega);
  const double K1 = 1.0 + (w * w - w0 * w0) / (Omega * Omega);
  // 16 elements: 1.1936 (8: 1.1964, 32: 1.1929): discretisation error ~3e-3 at 8 elements
  constexpr double kSouthwellTolerance = 2e-3;
  record("southwell_K1", K1, 1.1933);
  EXPECT_NEAR(K1 / 1.1933 - 1, 0.0, kSouthwellTolerance);
  // the linear FFR model about the unstretched state softens instead: omega^2 = omega_0^2 -
  // Omega^2, up to the Coriolis coupling with the axial modes (omega_a ~ 8000 rad/s):
  // a relative shift ~ 4 Omega^2 / omega_a^2 ~ 1e-5
  constexpr double kSofteningTolerance = 1e-4;
  const Scene s = parseScene(blade(Omega));
  ModesOptions o;
  o.count = 1;
  const double linear = modesAbout(s.system, initialReference(s.system), o).at(0).omega;
  EXPECT_NEAR(linear * linear / (w0 * w0 - Omega * Omega) - 1, 0.0, kSofteningTolerance);
}

namespace {

/// A symmetric top (mass 1, moments 0.01, 0.01, 0.02 about its centre of mass, 0.1 above
/// a spherical joint at the origin) sleeping: spinning at w about the vertical.
json sleepingTop(double w) {
  return {{"name", "sleeping top"},
          {"dimension", 3},
          {"gravity", {0, 0, -g}},
          {"bodies",
           {{{"name", "top"}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", {0.01, 0.01, 0.02}},
             {"position", {0, 0, 0.1}}, {"angular_velocity", {0, 0, w}}}}},
          {"joints",
           {{{"name", "S"}, {"type", "spherical"}, {"bodies", {"ground", "top"}},
             {"frames", {{{"point", {0, 0, 0}}}, {{"point", {0, 0, -0.1}}}}}}}},
          {"solver", {{"t_end", 1}}}};
}

}  // namespace

TEST(Linearization, SleepingTopIsStableAboveTheMaxwellKleinSpeedWithItsPrecessionFrequencies) {
  // The constraint Jacobian turns with the top (spherical joint away from the centre of
  // mass): the basis follows it (N', N''). Tilt xi = theta_x + i theta_y (Goldstein
  // sec. 5.7): I1 xi'' - i I3 w xi' - m g l xi = 0, I1 = 0.01 + m l^2 about the pivot:
  // stable when I3^2 w^2 > 4 I1 m g l (w > 14.0 rad/s).
  const double I1 = 0.01 + 0.1 * 0.1, I3 = 0.02, mgl = g * 0.1;
  // w = 10: unstable, s = (i I3 w +- sqrt(4 I1 m g l - I3^2 w^2)) / (2 I1)
  const double growth = std::sqrt(4 * I1 * mgl - I3 * I3 * 100) / (2 * I1);
  const std::vector<Mode> slow = modesOf(sleepingTop(10.0), 6);
  record("growth_rate", largestGrowthRate(slow), growth);
  EXPECT_NEAR(largestGrowthRate(slow) / growth - 1, 0.0, 1e-6);
  // w = 20: stable; precession frequencies (I3 w +- sqrt(I3^2 w^2 - 4 I1 m g l)) / (2 I1),
  // seen from the spinning body shifted by w: the same two magnitudes
  const double root = std::sqrt(I3 * I3 * 400 - 4 * I1 * mgl);
  const double fast = (I3 * 20 + root) / (2 * I1), slowPrecession = (I3 * 20 - root) / (2 * I1);
  const std::vector<Mode> modes = nonZero(modesOf(sleepingTop(20.0), 6));
  ASSERT_EQ(modes.size(), 2u);
  // G'' is a central difference (step 1e-4 of the motion): truncation ~1e-8
  constexpr double kTopTolerance = 1e-6;
  EXPECT_LT(largestGrowthRate(modes), kTopTolerance * fast);
  record("omega_slow_precession", modes[0].omega, slowPrecession);
  record("omega_fast_precession", modes[1].omega, fast);
  EXPECT_NEAR(modes[0].omega / slowPrecession - 1, 0.0, kTopTolerance);
  EXPECT_NEAR(modes[1].omega / fast - 1, 0.0, kTopTolerance);
}

TEST(Linearization, SpatialFreeFreeBeamHasSixRigidModesAndTheModelsElasticFrequencies) {
  // FfrBody3d (quaternion frame, T != I) from a free-free (mean-axis) beam model, free in
  // space: six zero eigenvalues, then the model's frequencies with its frame held fixed
  BeamSection3d sec;
  sec.area = kWidth * kHeight;
  sec.inertiaY = kWidth * kHeight * kHeight * kHeight / 12;
  sec.inertiaZ = kHeight * kWidth * kWidth * kWidth / 12;
  sec.torsionConstant = 0.229 * kWidth * kHeight * kHeight * kHeight;  // b/h = 2 (Roark)
  sec.youngsModulus = kE;
  sec.shearModulus = kE / 2.6;
  sec.density = kRho;
  FfrBeamOptions3d options;
  options.reference.type = ReferenceConditions3d::Type::FreeFree;
  const FfrBeamModel3d model(BeamMesh3d::straight(kBeamLength, 6, sec), options, "beam");
  System sys;
  FrameState3d frame;
  frame.orientation = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  sys.addBody(std::make_unique<FfrBody3d>("beam", model.invariants(), frame));
  sys.finalize();
  ModesOptions o;
  o.count = 12;
  const std::vector<Mode> modes = modesAbout(sys, initialReference(sys), o);
  ASSERT_EQ(modes.size(), 12u);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(modes[k].omega, 0.0) << "rigid mode " << k;
  const VecX w = model.naturalFrequencies();
  // as the planar free-free beam: rounding relative to the highest frequency (~1e4 x the lowest)
  constexpr double kModelTolerance = 1e-9;
  for (int k = 0; k < 6; ++k) {
    record("omega_elastic_" + std::to_string(k + 1), modes[6 + k].omega, w[k]);
    EXPECT_NEAR(modes[6 + k].omega / w[k] - 1, 0.0, kModelTolerance) << k;
  }
}

// ----- Campbell branches followed by shape (followBranches) ---------------------------

TEST(CampbellBranches, ModesThatSwapRanksAreFollowedByTheirShapes) {
  // Two modes whose frequencies cross between two speeds: by rank the lines would jump
  // from one shape to the other; followed by shape (modal assurance) each stays on its own.
  Mode a, b, c;
  a.shape = Eigen::VectorXcd::Zero(3);
  b.shape = Eigen::VectorXcd::Zero(3);
  c.shape = Eigen::VectorXcd::Zero(3);
  a.shape << 1.0, 0.1, 0.0;
  b.shape << 0.0, 1.0, 0.2;
  c.shape << 0.0, 0.0, 1.0;
  a.frequencyHz = 10.0, b.frequencyHz = 11.0, c.frequencyHz = 30.0;
  Mode a2 = a, b2 = b;
  a2.frequencyHz = 12.0;  // a stiffens past b
  b2.frequencyHz = 11.5;
  b2.shape *= std::complex<double>(0.0, -2.0);  // the same shape, scaled and turned in phase
  const std::vector<int> order = followBranches({a, b, c}, {b2, a2, c});
  EXPECT_EQ(order, (std::vector<int>{1, 0, 2}));
  EXPECT_NEAR(modalAssurance(b.shape, b2.shape), 1.0, 1e-15);
  EXPECT_NEAR(modalAssurance(a.shape, c.shape), 0.0, 1e-15);
  // the first speed: no earlier branches, the frequency order stays
  EXPECT_EQ(followBranches({}, {a, b, c}), (std::vector<int>{0, 1, 2}));
}

TEST(CampbellBranches, TheSpinningBladesCrossingModesStayOnTheirBranches) {
  // examples/spinning_blade.json swept from 0 to 120 rad/s (steady motion): its second and
  // third modes cross near 65 rad/s. Followed by shape, consecutive speeds' modes along a
  // branch have a modal assurance near 1 (>= 0.8: the shapes change a little with the
  // speed); by rank one step pairs two different shapes (the crossing), asserted below 0.5
  // so that the test tells the two orderings apart.
  json j = json::parse(std::ifstream(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spinning_blade.json"));
  ModesOptions o;
  o.count = 5;
  std::vector<Mode> previousByShape, previousByRank;
  double worstByShape = 1.0, worstByRank = 1.0;
  for (int i = 0; i <= 12; ++i) {
    j["drivers"][0]["law"]["speed"] = 10.0 * i;
    const Scene s = parseScene(j);
    const System& sys = s.system;
    const std::vector<Mode> found =
        modesAbout(sys, solveSteadyMotion(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities()), o);
    std::vector<Mode> byShape;
    for (int k : followBranches(previousByShape, found)) byShape.push_back(found[k]);
    if (i > 0) {
      for (int k = 0; k < 3; ++k) {
        worstByShape = std::min(worstByShape, modalAssurance(previousByShape[k].shape, byShape[k].shape));
        worstByRank = std::min(worstByRank, modalAssurance(previousByRank[k].shape, found[k].shape));
      }
    }
    previousByShape = byShape;
    previousByRank = found;
  }
  EXPECT_GE(worstByShape, 0.8);
  EXPECT_LT(worstByRank, 0.5);
  std::printf("[ figures ] spinning blade 0..120 rad/s, first 3 branches: worst consecutive MAC by shape %.3f, by "
              "rank %.3f\n", worstByShape, worstByRank);
}
