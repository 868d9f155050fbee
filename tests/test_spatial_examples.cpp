// The spatial example scenes of examples/ run here, each against a
// physical fact of it (docs/spatial.md, "Spatial examples"):
//  - examples/heavy_top.json: energy and the top's two angular momenta conserved, the
//    steady precession of Goldstein eq. 5.74 kept;
//  - examples/flyball_governor.json (IFToMM A05 parameters): the driver's work is the
//    change of energy; the steady rotation's arm angle is the closed-form equilibrium;
//  - examples/flexible_robot_arm.json: the joint torques' work is the change of kinetic,
//    elastic and gravity energy; a stiff second link follows the rigid two-link arm;
//  - examples/spinning_blade.json through `flexmbd modes --sweep`: Southwell's law for
//    the first flap mode, the propeller moment for the first torsional mode.
// Every tolerance is named and justified where it is used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bodies/rigid_body_3d.hpp"
#include "cli_fixture.hpp"
#include "core/rotation_3d.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
using nlohmann::json;

namespace {

json exampleJson(const std::string& file) {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + file);
  EXPECT_TRUE(in.good()) << file;
  return json::parse(in);
}

struct RunData {
  std::vector<double> t;
  std::vector<VecX> q, v, lambda;
  std::vector<std::vector<double>> outputs;  ///< the scene's outputs (OutputRequest::evaluate)
  long steps = 0;
};

/// Runs a parsed scene, keeping every output's state and the scene's requested outputs.
RunData runScene(Scene& scene) {
  RunData r;
  scene.solver.progress = false;
  const SimulationSummary sum = simulate(scene.system, scene.solver, [&](const OutputSample& s) {
    r.t.push_back(s.t);
    r.q.push_back(s.q);
    r.v.push_back(s.v);
    r.lambda.push_back(s.lambda);
    std::vector<double> row;
    for (const OutputRequest& o : scene.outputs) {
      const std::vector<double> x = o.evaluate(scene.system, s.q, s.v);
      row.insert(row.end(), x.begin(), x.end());
    }
    r.outputs.push_back(row);
  });
  EXPECT_TRUE(sum.ok) << sum.message;
  r.steps = sum.stats.steps;
  return r;
}

/// Composite Simpson's rule over equally spaced samples (an odd count; trapezoid on the
/// last interval otherwise).
double integrate(const std::vector<double>& t, const std::vector<double>& f) {
  const std::size_t n = f.size();
  if (n < 2) return 0.0;
  const double h = t[1] - t[0];
  double s = 0.0;
  std::size_t k = 0;
  for (; k + 2 < n; k += 2) s += h / 3.0 * (f[k] + 4.0 * f[k + 1] + f[k + 2]);
  if (k + 1 < n) s += 0.5 * h * (f[k] + f[k + 1]);
  return s;
}

}  // namespace

// ----- heavy top ------------------------------------------------------------------------

TEST(SpatialExample, HeavyTopKeepsItsIntegralsAndTheExactSteadyPrecession) {
  const json j = exampleJson("heavy_top.json");
  Scene scene = parseScene(j);
  const BodyIndex b = scene.system.findBody("top");
  const auto& top = dynamic_cast<const RigidBody3d&>(scene.system.body(b));
  const double m = top.mass(), g = -j["gravity"][2].get<double>();
  const Mat3 J = top.inertia();  // about the centre of mass, body axes (from the shape)
  const double I1 = J(0, 0), I3 = J(2, 2);
  const Vec3 r0(j["bodies"][0]["position"][0], j["bodies"][0]["position"][1], j["bodies"][0]["position"][2]);
  const double d = r0.norm(), tilt0 = std::acos(r0.z() / d);
  const double w3 = j["bodies"][0]["angular_velocity"][2];
  // Goldstein eq. 5.74, steady precession at tilt theta: with I1' = I1 + m d^2 (about the
  // tip) and w3 the spin component along the axis,
  //   I1' cos(theta) phi'^2 - I3 w3 phi' + m g d = 0;  the slow root:
  const double I1p = I1 + m * d * d, a = I1p * std::cos(tilt0), bq = I3 * w3, c = m * g * d;
  const double slow = (bq - std::sqrt(bq * bq - 4 * a * c)) / (2 * a);
  // the gyroscopic approximation m g d / (I3 w3) is the first term of
  // slow = (m g d / I3 w3) (1 + eps + 2 eps^2 + 5 eps^3 + ...), eps = a m g d / (I3 w3)^2:
  // its relative error lies between eps and eps / (1 - 4 eps)
  const double gyro = c / bq, eps = a * c / (bq * bq);

  const RunData run = runScene(scene);
  ASSERT_GT(run.t.size(), 100u);
  const int oq = scene.system.coordinateOffset(b), ov = scene.system.velocityOffset(b);
  auto state = [&](std::size_t k, Vec3& r, Vec3& rd, Mat3& A, Vec3& w) {
    r = run.q[k].segment<3>(oq);
    A = quaternionRotation(Vec4(run.q[k].segment<4>(oq + 3)));
    rd = run.v[k].segment<3>(ov);
    w = run.v[k].segment<3>(ov + 3);  // body axes
  };
  double E0 = 0, Lz0 = 0, L30 = 0, dE = 0, dLz = 0, dL3 = 0, dTilt = 0, azimuthErr = 0;
  double azimuth = 0, previous = 0;
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    Vec3 r, rd, w;
    Mat3 A;
    state(k, r, rd, A, w);
    const double E = 0.5 * m * rd.squaredNorm() + 0.5 * w.dot(J * w) + m * g * r.z();
    const Vec3 L = m * r.cross(rd) + A * (J * w);  // about the tip (the fixed point), world axes
    const Vec3 e3 = A.col(2);
    const double Lz = L.z(), L3 = L.dot(e3);
    const double tilt = std::acos(std::clamp(e3.z(), -1.0, 1.0));
    const double az = std::atan2(e3.y(), e3.x());
    if (k == 0) {
      E0 = E, Lz0 = Lz, L30 = L3, previous = az;
    }
    azimuth += std::remainder(az - previous, 2 * M_PI);
    previous = az;
    dE = std::max(dE, std::abs(E - E0));
    dLz = std::max(dLz, std::abs(Lz - Lz0));
    dL3 = std::max(dL3, std::abs(L3 - L30));
    dTilt = std::max(dTilt, std::abs(tilt - tilt0));
    azimuthErr = std::max(azimuthErr, std::abs(azimuth - slow * run.t[k]));
  }
  const double T = run.t.back();
  std::printf("[ figures ] heavy top over %.3f s (%ld steps): energy drift %.3e J of %.4f J; Lz drift %.3e, "
              "L3 drift %.3e kg m^2/s (L3 = %.6f); tilt error %.3e rad; azimuth error %.3e rad of %.4f "
              "(precession %.6f rad/s exact, measured mean %.6f; gyroscopic approximation %.6f, off by %.4f, "
              "eps = %.4f)\n",
              T, run.steps, dE, 0.5 * w3 * w3 * I3, dLz, dL3, L30, dTilt, azimuthErr, slow * T, slow,
              azimuth / T, gyro, slow / gyro - 1, eps);
  // the approximation's error bound stated above, checked on the exact root
  EXPECT_GE(slow / gyro - 1, eps);
  EXPECT_LE(slow / gyro - 1, eps / (1 - 4 * eps));
  // Tolerances: at the file's rtol 1e-9 over ~700 spin periods (~9e4 steps) the measured
  // drifts are 4.5e-10 (energy, relative to 56 J), 2.4e-8 (Lz, relative to L3 = 0.375)
  // and 6e-8 rad (tilt, azimuth): the BDF's error accumulated over the steps. Bounds
  // kConserved 1e-7 relative and kAngle 1e-6 rad leave 4x to 20x for other step sequences,
  // and lie far below what a wrong gyroscopic or gravity term would give (the precession
  // rate moves by O(1): the gyroscopic approximation alone is 7% off).
  constexpr double kConserved = 1e-7, kAngle = 1e-6;
  EXPECT_LE(dE, kConserved * 0.5 * I3 * w3 * w3);
  EXPECT_LE(dLz, kConserved * std::abs(L30));
  EXPECT_LE(dL3, kConserved * std::abs(L30));
  EXPECT_LE(dTilt, kAngle);
  EXPECT_LE(azimuthErr, kAngle);
  EXPECT_GT(azimuth, 2 * M_PI);  // a whole precession turn
}

// ----- spinning blade: Campbell diagram -------------------------------------------------

namespace {

/// The rows of a campbell.csv (speed, f1_hz, f2_hz, ..., zeta...), header checked.
std::vector<std::vector<double>> readCampbell(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("speed,f1_hz,f2_hz,f3_hz", 0), 0u) << line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_F(Cli, SpatialExampleSpinningBladeFollowsSouthwellAndThePropellerMoment) {
  // `flexmbd modes examples/spinning_blade.json --steady --sweep motor:0:40:5`: the blade
  // linearised about its steady stretched state at 0, 10, ..., 40 rad/s.
  const std::string scene = std::string(FLEXMBD_SOURCE_DIR) + "/examples/spinning_blade.json";
  const json j = exampleJson("spinning_blade.json");
  const json& s = j["bodies"][0]["section"];
  const double A = s["area"], Iy = s["inertia_y"], Iz = s["inertia_z"], Jt = s["torsion_constant"];
  const double E = s["youngs_modulus"], G = s["shear_modulus"], rho = s["density"];
  const double L = j["bodies"][0]["beam"]["length"];
  const fs::path out = dir_ / "campbell";
  const CliResult r = run("modes " + shellQuote(scene) + " --out " + shellQuote(out.string()) +
                          " --count 3 --steady --sweep motor:0:40:5 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "campbell.png"));
  const std::vector<std::vector<double>> rows = readCampbell(out / "campbell.csv");
  ASSERT_EQ(rows.size(), 5u);
  // Which column is which: at rest the first is the clamped-free torsion mode
  // (pi / 2L) sqrt(G J / rho Ip), the second the first flap mode 3.5160 / L^2 sqrt(E Iy /
  // rho A) (Iy: bending out of the plane of rotation). Discretisation of 16 elements:
  // linear twist (pi / 32)^2 / 12 ~ 1e-3, the cubic beam's first mode ~1e-6: 2e-3, 1e-4.
  const double Ip = Iy + Iz;
  const double torsion0 = M_PI / (2 * L) * std::sqrt(G * Jt / (rho * Ip));
  const double flap0 = 3.5160152 / (L * L) * std::sqrt(E * Iy / (rho * A));
  const double wt0 = 2 * M_PI * rows[0][1], wf0 = 2 * M_PI * rows[0][2];
  EXPECT_NEAR(wt0 / torsion0, 1.0, 2e-3);
  EXPECT_NEAR(wf0 / flap0, 1.0, 1e-4);
  // Southwell: omega^2 = omega0^2 + K Omega^2. The first flap mode of a uniform cantilever
  // with zero hub radius has K -> 1.1933 as Omega -> 0 (Wright, Smith, Thresher and Wang,
  // J. Appl. Mech. 49 (1982); docs/modes.md). kSouthwellSmall 2e-3 at the lowest speed:
  // the 16-element mesh lies ~1e-3 above the continuum (8 elements: 3.9e-3; it converges as
  // h^2), and K itself falls slightly with Omega (by 3.2e-3 from 10 to 40 rad/s here); over
  // the whole sweep K stays within kSouthwellRange of 1.19.
  // Propeller moment: omega_t^2 = omega_t0^2 + Omega^2 (Iz - Iy) / Ip, the rigid-section
  // law, exact for the discrete model (tests/test_spinning_beam_torsion.cpp); the engine's
  // element has no Wagner (trapeze) term, so the centrifugal tension does not add to it.
  // kPropeller 1e-6 on the coefficient: the CSV's 12 digits and the eigensolver's
  // round-off (1e-7 on omega^2 there) seen through Omega^2 c / omega^2 >= 0.06.
  constexpr double kSouthwellSmall = 2e-3, kSouthwellRange = 0.01, kPropeller = 1e-6;
  const double propeller = (Iz - Iy) / Ip;
  std::printf("[ figures ] spinning blade at rest: torsion %.6f rad/s (continuum %.6f), flap %.6f (continuum %.6f)\n",
              wt0, torsion0, wf0, flap0);
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const double Om = rows[k][0], wt = 2 * M_PI * rows[k][1], wf = 2 * M_PI * rows[k][2];
    const double K = (wf * wf - wf0 * wf0) / (Om * Om), c = (wt * wt - wt0 * wt0) / (Om * Om);
    std::printf("[ figures ] spinning blade at %4.0f rad/s: flap %.6f rad/s, Southwell K %.6f (1.1933); torsion "
                "%.6f rad/s, coefficient %.9f ((Iz - Iy) / Ip = %.6f)\n",
                Om, wf, K, wt, c, propeller);
    if (k == 1) EXPECT_NEAR(K, 1.1933, kSouthwellSmall);
    EXPECT_NEAR(K, 1.19, kSouthwellRange) << Om;
    EXPECT_NEAR(c, propeller, kPropeller) << Om;
  }
}

// ----- Rayleigh rotor: forward and backward whirl -----------------------------------------

TEST_F(Cli, SpatialExampleRayleighRotorWhirlsForwardAndBackwardAndKeepsItsTorsion) {
  // `flexmbd modes examples/rayleigh_rotor.json --sweep motor:0:600:4 --count 5`, and the
  // same scene with "beam_theory": "euler_bernoulli". The body frame turns with the shaft,
  // so an axisymmetric rotor's whirl at omega_F (forward) and omega_B (backward) in the
  // fixed frame is seen at omega_F - Omega and omega_B + Omega (f1, f2 of the first
  // bending pair): the gyroscopic split is s = omega_F - omega_B = 2 Omega - (w2 - w1).
  // Facts: (1) Euler-Bernoulli (no rotary inertia, no gyroscopic moment): s = 0; (2)
  // Rayleigh: s > 0 and, to first order in Omega, s / Omega = Ip Q / (A + I Q) with
  // Q = int phi'^2 dx / int phi^2 dx of the non-rotating mode phi (the gyroscopic term's
  // Rayleigh quotient; for a sine mode Q = k^2, the simply supported closed form of Genta,
  // Dynamics of Rotating Systems, sec. 4.9): here phi is the clamped-pinned mode
  // cosh bx - cos bx - sigma (sinh bx - sin bx), bL = 3.9266023; (3) the torsion mode (f5)
  // does not move with the spin (the sections' second-order rotation).
  //  - kNoSplit 1e-6 rad/s per rad/s of spin: the CSV's 12 digits on ~200 Hz and the
  //    eigensolver's round-off (1e-9 relative) against s ~ 0.004 Omega.
  //  - kLinear 2e-2: s / Omega varies with Omega only through the gyroscopic coupling to the
  //    higher modes (second order in Omega rho Ip k^2 / (m omega): ~1e-3 here); 2e-2 with margin.
  //  - kTorsion 1e-9: the torsion frequency at each speed is the same eigenvalue of the same
  //    matrices (the spin terms cancel exactly in the twist block): CSV digits.
  //  - kRatio 1e-3 against the Rayleigh quotient: the 8-element mode's error (~1e-5), the
  //    second-order coupling above, the quotient's midpoint quadrature (4000 points, ~1e-7).
  constexpr double kNoSplit = 1e-6, kLinear = 2e-2, kTorsion = 1e-9, kRatio = 1e-3;
  const json j = exampleJson("rayleigh_rotor.json");
  ASSERT_EQ(j["bodies"][0]["beam_theory"], "rayleigh");
  json eb = j;
  eb["bodies"][0]["beam_theory"] = "euler_bernoulli";
  const fs::path ebScene = dir_ / "rotor_eb.json";
  std::ofstream(ebScene) << eb.dump(1);
  const std::string rayScene = std::string(FLEXMBD_SOURCE_DIR) + "/examples/rayleigh_rotor.json";
  auto sweep = [&](const std::string& scene, const std::string& name) {
    const fs::path out = dir_ / name;
    const CliResult r = run("modes " + shellQuote(scene) + " --out " + shellQuote(out.string()) +
                            " --count 5 --sweep motor:0:600:4 --quiet");
    EXPECT_EQ(r.status, 0) << r.err;
    return readCampbell(out / "campbell.csv");
  };
  const auto ray = sweep(rayScene, "rayleigh"), ebr = sweep(ebScene.string(), "euler_bernoulli");
  ASSERT_EQ(ray.size(), 4u);
  ASSERT_EQ(ebr.size(), 4u);
  const json& sec = j["bodies"][0]["section"];
  const double A = sec["area"], I = sec["inertia_z"], Ip = I + sec["inertia_y"].get<double>();
  const double L = j["bodies"][0]["beam"]["length"], b = 3.9266023 / L;
  const double sigma = (std::cosh(b * L) - std::cos(b * L)) / (std::sinh(b * L) - std::sin(b * L));
  double phi2 = 0, dphi2 = 0;
  for (int i = 0; i < 4000; ++i) {
    const double x = (i + 0.5) * L / 4000;
    const double phi = std::cosh(b * x) - std::cos(b * x) - sigma * (std::sinh(b * x) - std::sin(b * x));
    const double dphi = b * (std::sinh(b * x) + std::sin(b * x) - sigma * (std::cosh(b * x) - std::cos(b * x)));
    phi2 += phi * phi;
    dphi2 += dphi * dphi;
  }
  const double Q = dphi2 / phi2, continuum = Ip * Q / (A + I * Q);
  double first = 0;
  for (std::size_t n = 1; n < ray.size(); ++n) {
    const double Om = ray[n][0];
    const double s = 2 * Om - 2 * M_PI * (ray[n][2] - ray[n][1]);
    const double sEb = 2 * Om - 2 * M_PI * (ebr[n][2] - ebr[n][1]);
    std::printf("[ figures ] Rayleigh rotor at %3.0f rad/s: whirl %.6f / %.6f Hz (rotating frame), split %.6f rad/s, "
                "s / Omega %.7f (Rayleigh quotient %.7f); Euler-Bernoulli split %.2e; torsion %.9f Hz\n",
                Om, ray[n][1], ray[n][2], s, s / Om, continuum, sEb, ray[n][5]);
    if (n == 1) first = s / Om;
    EXPECT_GT(s, 0.0);
    EXPECT_NEAR(s / Om, first, kLinear * first) << Om;
    EXPECT_NEAR(s / Om, continuum, kRatio * continuum) << Om;
    EXPECT_LT(std::abs(sEb), kNoSplit * Om) << Om;
    EXPECT_NEAR(ray[n][5] / ray[0][5], 1.0, kTorsion) << Om;
  }
}

// ----- two-link robot arm with a flexible forearm ---------------------------------------

namespace {

/// A harmonic time law of the scene: offset + amplitude sin(omega t + phase).
double harmonic(const json& law, double t) {
  EXPECT_EQ(law["type"], "harmonic");
  return law.value("offset", 0.0) + law["amplitude"].get<double>() * std::sin(law["omega"].get<double>() * t +
                                                                            law.value("phase", 0.0));
}

/// World y component of a spatial body's angular velocity (its frame's; at a clamped
/// node of a flexible body, the node's section turns with the frame).
double omegaY(const System& sys, BodyIndex b, const VecX& q, const VecX& v) {
  const Mat3 A = quaternionRotation(Vec4(q.segment<4>(sys.coordinateOffset(b) + 3)));
  return (A * v.segment<3>(sys.velocityOffset(b) + 3)).y();
}

struct ArmEnergy {
  double work = 0, dE = 0, worst = 0, Eend = 0, elasticPeak = 0;
};

/// The arm scene `j` run: the joint torques' work against the change of the scene's energy
/// output (kinetic + gravity + elastic) at every output.
ArmEnergy armEnergyBalance(const json& j) {
  Scene scene = parseScene(j);
  const System& sys = scene.system;
  const BodyIndex upper = sys.findBody("upper_arm"), fore = sys.findBody("forearm");
  const json& f = j["forces"];
  EXPECT_EQ(f[0]["body"], "upper_arm");
  EXPECT_EQ(f[1]["body"], "forearm");  // the elbow torque on the forearm, at its clamped node 0
  EXPECT_EQ(f[2]["body"], "upper_arm");  // and its reaction
  const RunData run = runScene(scene);
  std::vector<double> power;
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    const double t = run.t[k];
    const double wu = omegaY(sys, upper, run.q[k], run.v[k]), wf = omegaY(sys, fore, run.q[k], run.v[k]);
    power.push_back(harmonic(f[0]["torque_y"], t) * wu + harmonic(f[1]["torque_y"], t) * wf +
                    harmonic(f[2]["torque_y"], t) * wu);
  }
  ArmEnergy e;
  const double E0 = run.outputs.front()[2];  // energy.total
  std::vector<double> tt, pp;
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    tt.push_back(run.t[k]);
    pp.push_back(power[k]);
    if (k % 2 == 0) {  // Simpson over an even number of intervals
      const double W = integrate(tt, pp), dE = run.outputs[k][2] - E0;
      e.worst = std::max(e.worst, std::abs(W - dE));
      e.work = W, e.dE = dE;
    }
  }
  e.Eend = run.outputs.back()[2];
  return e;
}

}  // namespace

TEST(SpatialExample, FlexibleRobotArmTorquesWorkIsTheChangeOfEnergy) {
  json j = exampleJson("flexible_robot_arm.json");
  // The work is integrated from the outputs (Simpson), and the power carries the
  // forearm's vibration (its 4 modes reach ~2600 rad/s): at the file's 1 ms outputs the
  // rule is off by 4.7e-4 J, at 0.5 ms by 3.4e-5 J (the h^4 of the rule: the integration
  // is not the limit, rtol 1e-10 changes neither). Outputs every 0.25 ms here.
  j["solver"]["output_step"] = 2.5e-4;
  const ArmEnergy e = armEnergyBalance(j);
  std::printf("[ figures ] flexible robot arm: work of the joint torques %.9f J, change of energy %.9f J; "
              "largest |W - dE| over the run %.3e J\n",
              e.work, e.dE, e.worst);
  EXPECT_GT(std::abs(e.work), 1.0);  // the torques do work of order joules
  // Tolerance kBalance 1e-5 J (of 1.76 J of work, energies of ~6 J): Simpson's rule at
  // 0.25 ms, (omega h)^4 / 180 ~ 1e-3 of the power's fastest (small) vibrating part and
  // h^4 = 1/16 of the 3.4e-5 J at 0.5 ms, ~2e-6 J; the run's rtol 1e-8 on ~6 J, ~1e-7 J.
  constexpr double kBalance = 1e-5;
  EXPECT_LE(e.worst, kBalance);
}

// ----- flyball governor (IFToMM A05 parameters) -----------------------------------------

namespace {

/// The governor of examples/flyball_governor.json as the scene gives it: arms (rod + ball)
/// of mass ma, centre of mass dc from the hinge, principal moments Ixx (along the arm) and
/// Ip (across), hinges e off the axis at height h, springs k, free length L0 from the arm
/// point `a` (from the hinge) to the sleeve's side e off the axis, sleeve mass ms.
struct Governor {
  double ma, dc, Ixx, Ip, e, h, k, L0, a, ms, g;
  /// The amended potential of a steady rotation at the spindle speed Om (arms alpha below
  /// the horizontal, sleeve at height s): gravity + springs - Om^2 I_axis / 2 (the
  /// relative equilibria of the driven governor are its stationary points; the spindle
  /// and sleeve add constants).
  double potential(double alpha, double s, double Om) const {
    const double ca = std::cos(alpha), sa = std::sin(alpha);
    const double xc = e + dc * ca, zc = h - dc * sa;
    const double Iaxis = Ixx * sa * sa + Ip * ca * ca + ma * xc * xc;
    const double l = std::hypot(a * ca, h - a * sa - s);
    return 2 * (ma * g * zc + 0.5 * k * (l - L0) * (l - L0) - 0.5 * Om * Om * Iaxis) + ms * g * s;
  }
  /// Its gradient (d/dalpha, d/ds), analytic: with dz = h - a sin(alpha) - s and
  /// l = sqrt((a cos alpha)^2 + dz^2),
  ///   dV/dalpha = 2 (-ma g dc cos + k (l - L0) dl/dalpha - Om^2 ((Ixx - Ip) sin cos - ma xc dc sin)),
  ///   dV/ds = -2 k (l - L0) dz / l + ms g.
  Eigen::Vector2d gradient(const Eigen::Vector2d& x, double Om) const {
    const double ca = std::cos(x[0]), sa = std::sin(x[0]);
    const double dz = h - a * sa - x[1], l = std::hypot(a * ca, dz), xc = e + dc * ca;
    const double dlda = (-a * a * ca * sa - dz * a * ca) / l;
    return {2 * (-ma * g * dc * ca + k * (l - L0) * dlda - Om * Om * ((Ixx - Ip) * sa * ca - ma * xc * dc * sa)),
            -2 * k * (l - L0) * dz / l + ms * g};
  }
  /// Newton on the gradient (Hessian by differences of it) from x.
  Eigen::Vector2d equilibrium(Eigen::Vector2d x, double Om) const {
    for (int it = 0; it < 30; ++it) {
      Eigen::Matrix2d H;
      const double d = 1e-7;
      for (int c = 0; c < 2; ++c) {
        Eigen::Vector2d xp = x, xm = x;
        xp[c] += d, xm[c] -= d;
        H.col(c) = (gradient(xp, Om) - gradient(xm, Om)) / (2 * d);
      }
      const Eigen::Vector2d dx = H.lu().solve(-gradient(x, Om));
      x += dx;
      if (dx.norm() < 1e-13) break;
    }
    return x;
  }
};

Governor governorOf(const json& j) {
  Governor gv;
  const json& arm = j["bodies"][2];
  EXPECT_EQ(arm["name"], "arm_right");
  gv.ma = arm["mass"], gv.Ixx = arm["inertia"][0], gv.Ip = arm["inertia"][1];
  const json& hinge = j["joints"][2]["world"]["point"];
  gv.e = hinge[0], gv.h = hinge[2];
  const Vec3 r(arm["position"][0], arm["position"][1], arm["position"][2]);
  gv.dc = (r - Vec3(gv.e, 0, gv.h)).norm();
  const json& spring = j["forces"][0];
  gv.k = spring["stiffness"], gv.L0 = spring["free_length"];
  gv.a = gv.dc + spring["points"][1][0].get<double>();  // the arm point, from the hinge
  EXPECT_NEAR(spring["points"][0][0].get<double>(), gv.e, 1e-15);  // the sleeve's side, e off the axis
  const json& sleeve = j["bodies"][1]["shape"];
  gv.ms = sleeve["density"].get<double>() * std::pow(sleeve["size"][0].get<double>(), 3);
  gv.g = -j["gravity"][2].get<double>();
  return gv;
}

/// Arm angle below the horizontal and sleeve height along a run.
void governorState(const System& sys, const VecX& q, double& alpha, double& s) {
  const BodyIndex arm = sys.findBody("arm_right"), sleeve = sys.findBody("sleeve");
  const Mat3 A = quaternionRotation(Vec4(q.segment<4>(sys.coordinateOffset(arm) + 3)));
  const Vec3 d = A.col(0);  // along the arm, from the hinge out
  alpha = std::atan2(-d.z(), std::hypot(d.x(), d.y()));
  s = q[sys.coordinateOffset(sleeve) + 2];
}

}  // namespace

TEST(SpatialExample, FlyballGovernorTurnsSteadilyAtTheClosedFormArmAngle) {
  const json j = exampleJson("flyball_governor.json");
  const Governor gv = governorOf(j);
  const double Om = j["drivers"][0]["law"]["speed"];
  const Eigen::Vector2d eq = gv.equilibrium(Eigen::Vector2d(0.5, 0.5), Om);
  // the potential's gradient checked against differences of it (the code of the two)
  {
    const Eigen::Vector2d x(0.4, 0.45);
    const double d = 1e-6;
    const Eigen::Vector2d fd((gv.potential(x[0] + d, x[1], Om) - gv.potential(x[0] - d, x[1], Om)) / (2 * d),
                             (gv.potential(x[0], x[1] + d, Om) - gv.potential(x[0], x[1] - d, Om)) / (2 * d));
    EXPECT_LE((fd - gv.gradient(x, Om)).norm(), 1e-5 * gv.gradient(x, Om).norm());
  }
  // how much the equilibrium moves with the speed: the test's resolution
  const Eigen::Vector2d eqFaster = gv.equilibrium(eq, 1.01 * Om);
  Scene scene = parseScene(j);
  const RunData run = runScene(scene);
  double dAlpha = 0, dS = 0;
  for (const VecX& q : run.q) {
    double alpha, s;
    governorState(scene.system, q, alpha, s);
    dAlpha = std::max(dAlpha, std::abs(alpha - eq[0]));
    dS = std::max(dS, std::abs(s - eq[1]));
  }
  std::printf("[ figures ] flyball governor at %.6f rad/s: closed-form equilibrium arm %.9f deg below the "
              "horizontal, sleeve %.9f m (1%% faster: %.6f deg); over %.1f s the arm stays within %.3e rad and the "
              "sleeve within %.3e m of it\n",
              Om, eq[0] * 180 / M_PI, eq[1], eqFaster[0] * 180 / M_PI, run.t.back(), dAlpha, dS);
  // Tolerances: the run starts on the configuration the file gives (30 deg, sleeve at
  // the springs' static stretch, 12 digits), the equilibrium to round-off; the BDF at
  // rtol 1e-8 then keeps the arm within 1e-6 rad and the sleeve within 7e-7 m (the slow
  // governor mode stirred by the integration error). kAngle 1e-5 rad and kSleeve 5e-6 m:
  // 10x above that, 3 orders below what 1% of speed moves the equilibrium (1.1e-2 rad,
  // ~1e-2 m of sleeve) and below the springs' static stretch (7e-5 m).
  constexpr double kAngle = 1e-5, kSleeve = 5e-6;
  EXPECT_NEAR(eq[0], M_PI / 6, kAngle);  // the published 30 deg is the steady rotation at this speed
  EXPECT_LE(dAlpha, kAngle);
  EXPECT_LE(dS, kSleeve);
  EXPECT_GT(std::abs(eqFaster[0] - eq[0]), 100 * kAngle);
}

TEST(SpatialExample, FlyballGovernorDriverWorkIsTheChangeOfEnergy) {
  // The governor spun up to 1.2 times its steady speed from the steady state (the
  // consistent start projects the bodies' velocities onto the new driver speed), without
  // the springs' dampers (their dissipation is not an output): the arms swing out and
  // back, and the motor's work, -lambda Om (M v' = Q - G^T lambda, so the driver's force
  // -G^T lambda delivers -lambda G v = -lambda Om), is the change of the total energy.
  json j = exampleJson("flyball_governor.json");
  const double Om = 1.2 * j["drivers"][0]["law"]["speed"].get<double>();
  j["drivers"][0]["law"]["speed"] = Om;
  for (auto& f : j["forces"]) f["damping"] = 0.0;
  j["solver"]["output_step"] = 1e-3;
  Scene scene = parseScene(j);
  const int motor = scene.system.constraintOffset(scene.system.findConstraint("motor"));
  const RunData run = runScene(scene);
  std::vector<double> tt, pp;
  double worst = 0, W = 0, dE = 0, alphaMin = 10, alphaMax = -10;
  for (std::size_t k = 0; k < run.t.size(); ++k) {
    tt.push_back(run.t[k]);
    pp.push_back(-run.lambda[k][motor] * Om);
    double alpha, s;
    governorState(scene.system, run.q[k], alpha, s);
    alphaMin = std::min(alphaMin, alpha), alphaMax = std::max(alphaMax, alpha);
    if (k % 2 == 0) {
      W = integrate(tt, pp), dE = run.outputs[k][2] - run.outputs[0][2];
      worst = std::max(worst, std::abs(W - dE));
    }
  }
  std::printf("[ figures ] flyball governor spun at 1.2 x: arm between %.4f and %.4f deg, motor work %.9f J, change "
              "of energy %.9f J, largest |W - dE| %.3e J (%ld steps)\n",
              alphaMin * 180 / M_PI, alphaMax * 180 / M_PI, W, dE, worst, run.steps);
  EXPECT_GT(alphaMax - alphaMin, 0.1);  // the arms swing
  EXPECT_GT(std::abs(W), 1.0);
  // kBalance 1e-4 J of ~200 J: Simpson at 1 ms on a power that carries the sleeve's
  // bounce on the undamped springs (~700 rad/s, (omega h)^4 / 180 ~ 1e-3 of its small
  // part), and rtol 1e-8 of 200 J, 2e-6 J.
  constexpr double kBalance = 1e-4;
  EXPECT_LE(worst, kBalance);
}
