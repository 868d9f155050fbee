// Validation of spatial rigid-body dynamics against closed forms: torque-free motion
// (conservation of energy and angular momentum, the intermediate-axis instability, the
// body-frame precession of a symmetric body), the heavy top's steady precession, the
// quaternion's length over a long run, and a spatial pendulum in a plane against the
// planar engine.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <string>

#include "bodies/rigid_body_2d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "builders/planar_builders.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "forces/spatial_forces.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"

using namespace flexmbd;

namespace {

constexpr double kGravity = 9.81;

std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

Mat3 rotationX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }

SolverSettings settings(double tEnd, double rtol, double outputStep) {
  SolverSettings st;
  st.rtol = rtol;
  st.atol = rtol * 1e-2;
  st.tEnd = tEnd;
  st.outputStep = outputStep;
  st.progress = false;
  return st;
}

/// A free body with principal moments J (body axes) spinning at w0 (body axes).
System freeBody(const Vec3& J, const Vec3& w0) {
  System sys;
  RigidBody3dProperties p;
  p.mass = 2.0;
  p.inertia = J.asDiagonal();
  FrameState3d s;
  s.orientation = rotationX(0.3);
  s.velocity = Vec3(0.1, -0.2, 0.3);
  s.angularVelocity = w0;
  sys.addBody(std::make_unique<RigidBody3d>("body", p, s));
  sys.finalize();
  return sys;
}

Vec3 angularMomentum(const System& sys, const VecX& q, const VecX& v) {
  const auto& b = dynamic_cast<const RigidBody3d&>(sys.body(BodyIndex(1)));
  return RigidBody3d::rotationOf(q.segment(sys.coordinateOffset(BodyIndex(1)), 7)) *
         (b.inertia() * v.segment<3>(sys.velocityOffset(BodyIndex(1)) + 3));
}

/// A symmetric top (mass m, moments Ic about its centre of mass, I3 about its axis) on a
/// spherical joint at its tip, its centre of mass l up its axis, tilted by theta about world
/// x, turning at wBody (body axes) about the fixed tip; gravity along -z. The top is body 1.
System heavyTop(double m, double l, double Ic, double I3, double theta, const Vec3& wBody) {
  System sys;
  sys.setGravity(Vec3(0.0, 0.0, -kGravity));
  RigidBody3dProperties p;
  p.mass = m;
  p.inertia = Vec3(Ic, Ic, I3).asDiagonal();
  FrameState3d s0;
  s0.orientation = rotationX(theta);
  s0.position = s0.orientation * Vec3(0.0, 0.0, l);
  s0.angularVelocity = wBody;
  s0.velocity = (s0.orientation * wBody).cross(s0.position);
  const BodyIndex top = sys.addBody(std::make_unique<RigidBody3d>("top", p, s0));
  JointFrame tip;
  tip.point = Vec3(0.0, 0.0, -l);
  sys.addConstraint(std::make_unique<SpatialJoint>("tip", SpatialJointType::Spherical, kGround, JointFrame{}, top, tip));
  sys.finalize();
  return sys;
}

}  // namespace

TEST(FreeRigidBody, AsymmetricBodyConservesEnergyAndAngularMomentum) {
  const System sys = freeBody(Vec3(1.0, 2.0, 3.0), Vec3(1.0, 2.0, -1.5));
  // rtol 1e-10 over 20 s (~10 tumbling periods): IDA's global error is a few 1e-9 of
  // the O(10) energy and momentum; 1e-7 relative bounds it with margin.
  constexpr double kConservationTol = 1e-7;
  double E0 = NAN, maxE = 0.0, maxH = 0.0;
  Vec3 H0;
  const SimulationSummary s = simulate(sys, settings(20.0, 1e-10, 0.05), [&](const OutputSample& o) {
    const double E = kineticEnergy(sys, o.q, o.v);
    const Vec3 H = angularMomentum(sys, o.q, o.v);
    if (std::isnan(E0)) {
      E0 = E;
      H0 = H;
    }
    maxE = std::max(maxE, std::abs(E - E0) / E0);
    maxH = std::max(maxH, (H - H0).norm() / H0.norm());
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(maxE, kConservationTol);
  EXPECT_LE(maxH, kConservationTol);
  RecordProperty("energy_drift", sci(maxE));
  RecordProperty("momentum_drift", sci(maxH));
}

TEST(FreeRigidBody, RotationAboutTheIntermediateAxisIsUnstableAboutTheOthersStable) {
  // Spin 2 rad/s about one principal axis with a 1e-3 perturbation of the others: about
  // the axes of least and greatest inertia the perturbation stays of its size (bounded
  // oscillation); about the intermediate axis it grows as exp(lambda t) with
  // lambda = w sqrt((I2 - I1)(I3 - I2) / (I1 I3)) = 2 sqrt(1 * 1 / 3) = 1.15 /s, so over
  // 20 s the body flips (the spin component changes sign).
  const Vec3 J(1.0, 2.0, 3.0);
  constexpr double kSpin = 2.0, kPerturbation = 1e-3;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 w0 = Vec3::Constant(kPerturbation);
    w0[axis] = kSpin;
    const System sys = freeBody(J, w0);
    double minSpin = kSpin, maxOther = 0.0;
    const SimulationSummary s = simulate(sys, settings(20.0, 1e-9, 0.02), [&](const OutputSample& o) {
      const Vec3 w = o.v.segment<3>(3);
      minSpin = std::min(minSpin, w[axis]);
      Vec3 other = w;
      other[axis] = 0.0;
      maxOther = std::max(maxOther, other.norm());
    });
    ASSERT_TRUE(s.ok) << s.message;
    if (axis == 1) {
      EXPECT_LT(minSpin, -0.9 * kSpin) << "the intermediate axis flips";
      EXPECT_GT(maxOther, 0.5 * kSpin);
    } else {
      // bounded: the perturbation stays within a small multiple of its size (the
      // linearised motion is an ellipse whose axes are in the ratio sqrt of inertia ratios)
      EXPECT_GT(minSpin, kSpin * (1.0 - 1e-5)) << "axis " << axis;
      EXPECT_LT(maxOther, 10.0 * kPerturbation) << "axis " << axis;
    }
  }
}

TEST(FreeRigidBody, SymmetricBodyPrecessesInTheBodyFrameAtTheClosedFormRate) {
  // I1 = I2 = I, I3: the body-frame angular velocity turns about the symmetry axis at
  // Omega = (I3 - I) / I w3 (Euler's equations), keeping w3 and |w_perp| constant.
  constexpr double I = 1.0, I3 = 1.6, w3 = 3.0, wp = 0.7;
  const double Omega = (I3 - I) / I * w3;
  const System sys = freeBody(Vec3(I, I, I3), Vec3(wp, 0.0, w3));
  // rtol 1e-10 over 10 s (~3 precession periods): the phase error is ~1e-8 rad.
  constexpr double kPhaseTol = 1e-6;
  double worst = 0.0;
  const SimulationSummary s = simulate(sys, settings(10.0, 1e-10, 0.05), [&](const OutputSample& o) {
    const Vec3 w = o.v.segment<3>(3);
    // I w1' = (I - I3) w2 w3, I w2' = (I3 - I) w3 w1: w1 + i w2 = wp exp(i Omega t)
    const Vec3 ref(wp * std::cos(Omega * o.t), wp * std::sin(Omega * o.t), w3);
    worst = std::max(worst, (w - ref).norm());
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(worst, kPhaseTol * wp);
  RecordProperty("max_error", sci(worst));
}

TEST(FreeRigidBody, QuaternionLengthStaysBoundedOverALongTumblingRun) {
  // The length of p is a gauge: T(q) is tangent to |p| = const, so it changes only by
  // the integrator's local errors. Over 200 s (~100 tumbling periods, ~1e5 steps at
  // rtol 1e-8) it must stay within 1e-5 of 1 (measured: see RecordProperty).
  const System sys = freeBody(Vec3(1.0, 2.0, 3.0), Vec3(1.0, 2.0, -1.5));
  double worst = 0.0;
  const SimulationSummary s = simulate(sys, settings(200.0, 1e-8, 0.1), [&](const OutputSample& o) {
    worst = std::max(worst, std::abs(o.q.segment<4>(3).norm() - 1.0));
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(worst, 1e-5);
  RecordProperty("max_length_error", sci(worst));
}

TEST(HeavyTop, SteadyPrecessionAtTheClosedFormRate) {
  // Symmetric top on a spherical joint at its tip, centre of mass l above it; tilt theta,
  // axial spin w3. Steady precession needs (Goldstein, Classical Mechanics, eq. 5.74)
  //   m g l = phi' (I3 w3 - I1 phi' cos theta),  I1 about the tip;
  // the slow root phi' is taken. The tilt must stay and the axis must turn at phi'.
  constexpr double m = 1.5, l = 0.2, Ic = 0.01, I3 = 0.012, theta = 0.5, w3 = 100.0;
  const double I1 = Ic + m * l * l;
  const double a = I1 * std::cos(theta), b = -I3 * w3, c = m * kGravity * l;
  const double phid = (-b - std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
  const System sys = heavyTop(m, l, Ic, I3, theta, Vec3(0.0, phid * std::sin(theta), w3));
  const BodyIndex top(1);
  // rtol 1e-10 over 2 s (phi' = 2.87 rad/s: 0.9 turn): tilt and azimuth errors ~1e-8.
  constexpr double kAngleTol = 1e-6;
  double worstTilt = 0.0, worstAzimuth = 0.0;
  const SimulationSummary s = simulate(sys, settings(2.0, 1e-10, 0.01), [&](const OutputSample& o) {
    const Vec3 axis = RigidBody3d::rotationOf(o.q.segment(sys.coordinateOffset(top), 7)).col(2);
    worstTilt = std::max(worstTilt, std::abs(std::acos(axis.z()) - theta));
    const double azimuth = std::atan2(axis.y(), axis.x());  // -pi/2 at t = 0
    worstAzimuth = std::max(worstAzimuth, std::abs(std::remainder(azimuth - (-M_PI / 2 + phid * o.t), 2 * M_PI)));
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(worstTilt, kAngleTol);
  EXPECT_LE(worstAzimuth, kAngleTol);
  RecordProperty("precession_rate", sci(phid));
  RecordProperty("tilt_error", sci(worstTilt));
  RecordProperty("azimuth_error", sci(worstAzimuth));
}

TEST(SpatialInPlane, PendulumOnARevoluteJointGivesThePlanarResult) {
  // The same physical pendulum as a planar body and as a spatial body on a revolute
  // joint about world z, gravity in -y: the angles agree to the integration error
  // (both at rtol 1e-11: ~1e-9 rad; bound 1e-7 rad).
  constexpr double m = 2.0, Ic = 0.05, L = 0.8, phi0 = 1.2;
  constexpr double kAgreement = 1e-7;
  System planar;
  planar.setGravity(Vec2(0.0, -kGravity));
  const BodyIndex bp = addRigidBody(planar, "bob", {m, Ic, {L, 0.0}}, {{0, 0}, phi0 - M_PI / 2});
  addRevoluteJoint(planar, "pivot", kGround, {0, 0}, bp, {0, 0});
  planar.finalize();
  System spatial;
  spatial.setGravity(Vec2(0.0, -kGravity));
  RigidBody3dProperties p;
  p.mass = m;
  p.inertia = Vec3(Ic, Ic, Ic).asDiagonal();
  FrameState3d s0;
  s0.orientation = Eigen::AngleAxisd(phi0 - M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  s0.position = s0.orientation * Vec3(L, 0.0, 0.0);
  const BodyIndex bs = spatial.addBody(std::make_unique<RigidBody3d>("bob", p, s0));
  JointFrame pin;
  pin.point = Vec3(-L, 0.0, 0.0);
  spatial.addConstraint(std::make_unique<SpatialJoint>("pivot", SpatialJointType::Revolute, kGround, JointFrame{}, bs, pin));
  spatial.finalize();
  std::vector<double> anglesPlanar, anglesSpatial;
  simulate(planar, settings(3.0, 1e-11, 0.05), [&](const OutputSample& o) { anglesPlanar.push_back(o.q[2]); });
  const SimulationSummary s = simulate(spatial, settings(3.0, 1e-11, 0.05), [&](const OutputSample& o) {
    const Mat3 A = RigidBody3d::rotationOf(o.q.segment(spatial.coordinateOffset(bs), 7));
    anglesSpatial.push_back(std::atan2(A(1, 0), A(0, 0)));
    EXPECT_LE(std::abs(A(2, 2) - 1.0), 1e-9);  // stays in the plane
  });
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(anglesPlanar.size(), anglesSpatial.size());
  double worst = 0.0;
  for (size_t k = 0; k < anglesPlanar.size(); ++k) {
    worst = std::max(worst, std::abs(std::remainder(anglesPlanar[k] - anglesSpatial[k], 2 * M_PI)));
  }
  EXPECT_LE(worst, kAgreement);
  RecordProperty("max_angle_difference", sci(worst));
}

namespace {

/// Spatial slider crank: crank of radius r turning about world z at w; slider on a line
/// along x at height h above the crank plane; connecting rod of length L on a spherical
/// joint at the crank pin and a universal joint at the slider. With the crank pin at
/// P = r (cos th, sin th, 0) and the slider at S = (s, 0, h), |S - P| = L gives
///   s(th) = r cos th + D,  D = sqrt(L^2 - h^2 - r^2 sin^2 th),
///   s' = -r sin th - r^2 sin th cos th / D,
///   s'' = -r cos th - r^2 cos 2th / D - r^4 sin^2 th cos^2 th / D^3   (d/dth),
/// and x = s, x' = s' w, x'' = s'' w^2 at constant w.
struct SliderCrank3d {
  static constexpr double r = 0.15, L = 0.45, h = 0.1, w = 2.0 * M_PI, th0 = 0.3;
  static double D(double th) { return std::sqrt(L * L - h * h - r * r * std::sin(th) * std::sin(th)); }
  static double s(double th) { return r * std::cos(th) + D(th); }
  static double ds(double th) { return -r * std::sin(th) - r * r * std::sin(th) * std::cos(th) / D(th); }
  static double dds(double th) {
    const double sc = std::sin(th) * std::cos(th), d = D(th);
    return -r * std::cos(th) - r * r * std::cos(2.0 * th) / d - std::pow(r, 4) * sc * sc / (d * d * d);
  }
};

}  // namespace

TEST(SpatialSliderCrank, SliderPositionVelocityAndAccelerationMatchTheClosedForm) {
  using C = SliderCrank3d;
  System sys;
  sys.setGravity(Vec3(0.0, 0.0, -kGravity));
  auto box = [](double m, const Vec3& size) {
    RigidBody3dProperties p;
    p.mass = m;
    p.inertia = (m / 12.0 * Vec3(size.y() * size.y() + size.z() * size.z(), size.x() * size.x() + size.z() * size.z(),
                                 size.x() * size.x() + size.y() * size.y()))
                    .asDiagonal();
    return p;
  };
  // crank: body x axis along the crank, centre of mass at mid-length
  FrameState3d crank0;
  crank0.orientation = Eigen::AngleAxisd(C::th0, Vec3::UnitZ()).toRotationMatrix();
  crank0.position = crank0.orientation * Vec3(C::r / 2, 0.0, 0.0);
  const BodyIndex crank = sys.addBody(std::make_unique<RigidBody3d>("crank", box(1.0, Vec3(C::r, 0.02, 0.02)), crank0));
  // rod: body x axis from the crank pin P to the slider S
  const Vec3 P = C::r * Vec3(std::cos(C::th0), std::sin(C::th0), 0.0), S(C::s(C::th0), 0.0, C::h);
  const Vec3 e1 = (S - P).normalized(), cross = e1.cross(Vec3::UnitY()).normalized();
  FrameState3d rod0;
  rod0.orientation.col(0) = e1;
  rod0.orientation.col(1) = cross.cross(e1);
  rod0.orientation.col(2) = cross;
  rod0.position = 0.5 * (P + S);
  const BodyIndex rod = sys.addBody(std::make_unique<RigidBody3d>("rod", box(0.5, Vec3(C::L, 0.02, 0.02)), rod0));
  FrameState3d slider0;
  slider0.position = S;
  const BodyIndex slider = sys.addBody(std::make_unique<RigidBody3d>("slider", box(2.0, Vec3(0.1, 0.05, 0.05)), slider0));
  // joints
  JointFrame origin, crankAxis, crankPin, rodEnd, rodStart, sliderCross, rail;
  crankAxis.point = Vec3(-C::r / 2, 0.0, 0.0);
  crankPin.point = Vec3(C::r / 2, 0.0, 0.0);
  rodStart.point = Vec3(-C::L / 2, 0.0, 0.0);
  rodEnd.point = Vec3(C::L / 2, 0.0, 0.0);
  // the cross: frame x on the slider along world y, frame y on the rod along `cross` (rod
  // body axis z): perpendicular at the start, kept so by the universal joint
  sliderCross.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  rodEnd.axes.col(0) = Vec3::UnitY();
  rodEnd.axes.col(1) = Vec3::UnitZ();
  rodEnd.axes.col(2) = Vec3::UnitX();
  rail.axes.col(0) = Vec3::UnitY();  // prismatic along frame z = world x
  rail.axes.col(1) = Vec3::UnitZ();
  rail.axes.col(2) = Vec3::UnitX();
  rail.point = Vec3(0.0, 0.0, C::h);
  JointFrame railOnSlider = rail;
  railOnSlider.point = Vec3::Zero();
  sys.addConstraint(std::make_unique<SpatialJoint>("bearing", SpatialJointType::Revolute, kGround, origin, crank, crankAxis));
  sys.addConstraint(std::make_unique<SpatialJoint>("pin", SpatialJointType::Spherical, crank, crankPin, rod, rodStart));
  sys.addConstraint(std::make_unique<SpatialJoint>("cardan", SpatialJointType::Universal, slider, sliderCross, rod, rodEnd));
  sys.addConstraint(std::make_unique<SpatialJoint>("rail", SpatialJointType::Prismatic, kGround, rail, slider, railOnSlider));
  sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, origin, crank, crankAxis,
                                                             makeConstantSpeedLaw(C::w, C::th0)));
  sys.finalize();
  // rtol 1e-10 over 2 revolutions: positions to ~1e-10 m; accelerations are recomputed
  // from (q, v) at each output, so they carry the state's error times the O(w^2) scale:
  // bounds 1e-8 m, 1e-7 m/s, 1e-6 m/s^2 (against s ~ 0.5 m, s' ~ 1 m/s, s'' ~ 10 m/s^2).
  double ex = 0.0, ev = 0.0, ea = 0.0;
  const int xs = sys.coordinateOffset(slider), vs = sys.velocityOffset(slider);
  const SimulationSummary s = simulate(sys, settings(2.0, 1e-10, 0.01), [&](const OutputSample& o) {
    const double th = C::th0 + C::w * o.t;
    ex = std::max(ex, std::abs(o.q[xs] - C::s(th)));
    ev = std::max(ev, std::abs(o.v[vs] - C::ds(th) * C::w));
    ea = std::max(ea, std::abs(o.a[vs] - C::dds(th) * C::w * C::w));
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(ex, 1e-8);
  EXPECT_LE(ev, 1e-7);
  EXPECT_LE(ea, 1e-6);
  RecordProperty("position_error", sci(ex));
  RecordProperty("velocity_error", sci(ev));
  RecordProperty("acceleration_error", sci(ea));
}

TEST(SpatialRedundancy, FourBarWithParallelRevolutesIsReportedNamingTheDependentJoints) {
  // A planar four-bar built of spatial bodies and four revolute joints with parallel axes:
  // 18 velocities, 20 equations, 1 degree of freedom: 3 equations are redundant (the
  // out-of-plane ones of the last joint). With "redundant_constraints": "refuse" the model
  // error names the dependent equations (resolved by default: test_redundant_constraints).
  System sys;
  const Vec3 A(0, 0, 0), B(0.5, std::sqrt(3.0) / 2, 0), C(3.016007650436934, 2.4999487505001956, 0), D(3, 0, 0);
  auto link = [&](const std::string& name, const Vec3& p, const Vec3& q) {
    FrameState3d s;
    const Vec3 e = (q - p).normalized();
    s.orientation << e.x(), -e.y(), 0, e.y(), e.x(), 0, 0, 0, 1;
    s.position = 0.5 * (p + q);
    RigidBody3dProperties props;
    props.inertia = Vec3(0.01, 0.1, 0.1).asDiagonal();
    return sys.addBody(std::make_unique<RigidBody3d>(name, props, s));
  };
  const BodyIndex crank = link("crank", A, B), coupler = link("coupler", B, C), rocker = link("rocker", D, C);
  auto end = [](double half) {
    JointFrame f;
    f.point = Vec3(half, 0, 0);
    return f;
  };
  JointFrame atA, atD;
  atD.point = D;
  sys.addConstraint(std::make_unique<SpatialJoint>("A", SpatialJointType::Revolute, kGround, atA, crank, end(-0.5)));
  sys.addConstraint(std::make_unique<SpatialJoint>("B", SpatialJointType::Revolute, crank, end(0.5), coupler, end(-1.5)));
  sys.addConstraint(std::make_unique<SpatialJoint>("D", SpatialJointType::Revolute, kGround, atD, rocker, end(-1.25)));
  sys.addConstraint(std::make_unique<SpatialJoint>("C", SpatialJointType::Revolute, coupler, end(1.5), rocker, end(1.25)));
  sys.finalize();
  try {
    SolverSettings refuse = settings(0.1, 1e-8, 0.01);
    refuse.redundantConstraints = RedundantConstraints::Refuse;
    simulate(sys, refuse, nullptr);
    ADD_FAILURE() << "expected a ModelError for the redundant joints";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("redundant"), std::string::npos) << what;
    EXPECT_NE(what.find("joint 'C'"), std::string::npos) << what;
    RecordProperty("message", what);
  }
}

TEST(SpatialInPlane, SliderCrankGivesThePlanarPositionsAndDrivingTorque) {
  // examples/slider_crank_rigid.json (crank 1, rod 2, driven at 1 rad/s from the dead
  // centre) rebuilt of spatial bodies in the x-y plane: revolute bearing, spherical crank
  // pin, universal joint at the slider, prismatic rail (non-redundant in space). Both at
  // rtol 1e-10: slider position and motor torque agree to the integration error (~1e-9;
  // bounds 1e-7 m and 1e-6 relative to the largest torque).
  Scene planar = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json");
  planar.solver.rtol = 1e-10;
  planar.solver.atol = 1e-12;
  planar.solver.progress = false;
  System sys;
  auto body = [&](const std::string& name, double m, double Izz, const Vec3& com) {
    RigidBody3dProperties p;
    p.mass = m;
    p.inertia = Vec3(0.6 * Izz, 0.6 * Izz, Izz).asDiagonal();
    FrameState3d s;
    s.position = com;
    return sys.addBody(std::make_unique<RigidBody3d>(name, p, s));
  };
  const BodyIndex crank = body("crank", 1.0, 0.1, Vec3(0.5, 0, 0));
  const BodyIndex rod = body("rod", 1.0, 0.4, Vec3(2.0, 0, 0));
  const BodyIndex slider = body("slider", 0.5, 0.01, Vec3(3.0, 0, 0));
  JointFrame origin, crankAxis, crankPin, rodStart, rodEnd, sliderCross, rail, railOnSlider;
  crankAxis.point = Vec3(-0.5, 0, 0);
  crankPin.point = Vec3(0.5, 0, 0);
  rodStart.point = Vec3(-1.0, 0, 0);
  rodEnd.point = Vec3(1.0, 0, 0);
  sliderCross.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // x along world y
  rodEnd.axes.col(0) = Vec3::UnitY();
  rodEnd.axes.col(1) = Vec3::UnitZ();  // the cross: y along rod axis z = x_rod x y_world
  rodEnd.axes.col(2) = Vec3::UnitX();
  rail.axes.col(0) = Vec3::UnitY();
  rail.axes.col(1) = Vec3::UnitZ();
  rail.axes.col(2) = Vec3::UnitX();
  railOnSlider.axes = rail.axes;
  const ConstraintIndex bearing = sys.addConstraint(
      std::make_unique<SpatialJoint>("O1", SpatialJointType::Revolute, kGround, origin, crank, crankAxis));
  sys.addConstraint(std::make_unique<SpatialJoint>("O2", SpatialJointType::Spherical, crank, crankPin, rod, rodStart));
  sys.addConstraint(std::make_unique<SpatialJoint>("O3", SpatialJointType::Universal, slider, sliderCross, rod, rodEnd));
  sys.addConstraint(std::make_unique<SpatialJoint>("P", SpatialJointType::Prismatic, kGround, rail, slider, railOnSlider));
  const ConstraintIndex motor = sys.addConstraint(std::make_unique<SpatialJointAngleDriver>(
      "motor", kGround, origin, crank, crankAxis, makeConstantSpeedLaw(1.0, 0.0)));
  (void)bearing;
  sys.finalize();
  std::vector<double> xp, tp, xs, ts;
  const int xPlanar = planar.system.coordinateOffset(planar.system.findBody("slider"));
  const int motorPlanar = planar.system.constraintOffset(planar.system.findConstraint("motor"));
  ASSERT_TRUE(simulate(planar.system, planar.solver, [&](const OutputSample& o) {
                xp.push_back(o.q[xPlanar]);
                tp.push_back(-o.lambda[motorPlanar]);
              }).ok);
  SolverSettings st = planar.solver;
  const int xSpatial = sys.coordinateOffset(slider), motorSpatial = sys.constraintOffset(motor);
  const SimulationSummary s = simulate(sys, st, [&](const OutputSample& o) {
    xs.push_back(o.q[xSpatial]);
    ts.push_back(-o.lambda[motorSpatial]);
  });
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(xp.size(), xs.size());
  double ex = 0.0, et = 0.0, tmax = 0.0;
  for (size_t k = 0; k < xp.size(); ++k) {
    ex = std::max(ex, std::abs(xp[k] - xs[k]));
    et = std::max(et, std::abs(tp[k] - ts[k]));
    tmax = std::max(tmax, std::abs(tp[k]));
  }
  EXPECT_LE(ex, 1e-7);
  EXPECT_LE(et, 1e-6 * tmax);
  RecordProperty("position_difference", sci(ex));
  RecordProperty("torque_difference_relative", sci(et / tmax));
}

TEST(HeavyTop, NutationStaysBetweenTheClosedFormBounds) {
  // Released with spin w3 at tilt theta0 without precession or nutation rate: with
  // u = cos(theta), u'^2 = (u0 - u) [beta (1 - u^2) - a^2 (u0 - u)], a = I3 w3 / I1,
  // beta = 2 m g l / I1 (Goldstein, Classical Mechanics, sec. 5.7), so theta oscillates
  // between theta0 and acos(u1), u1 = (a^2 - sqrt(a^4 - 4 beta a^2 u0 + 4 beta^2)) / (2 beta).
  constexpr double m = 1.5, l = 0.2, Ic = 0.01, I3 = 0.012, theta0 = 0.5, w3 = 40.0;
  const double I1 = Ic + m * l * l, a = I3 * w3 / I1, beta = 2.0 * m * kGravity * l / I1, u0 = std::cos(theta0);
  const double u1 = (a * a - std::sqrt(std::pow(a, 4) - 4.0 * beta * a * a * u0 + 4.0 * beta * beta)) / (2.0 * beta);
  const double theta1 = std::acos(u1);
  const System sys = heavyTop(m, l, Ic, I3, theta0, Vec3(0.0, 0.0, w3));
  const BodyIndex top(1);
  // rtol 1e-10 over 2 s (several nutation periods, output every 0.2 ms so the extremes
  // are sampled to (omega_n dt)^2 ~ 1e-6 of the amplitude): bounds to 1e-5 rad
  constexpr double kBoundTol = 1e-5;
  double lo = 10.0, hi = -10.0;
  const SimulationSummary s = simulate(sys, settings(2.0, 1e-10, 2e-4), [&](const OutputSample& o) {
    const double tilt = std::acos(RigidBody3d::rotationOf(o.q.segment(sys.coordinateOffset(top), 7))(2, 2));
    lo = std::min(lo, tilt);
    hi = std::max(hi, tilt);
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_NEAR(lo, theta0, kBoundTol);
  EXPECT_NEAR(hi, theta1, kBoundTol);
  EXPECT_GT(theta1 - theta0, 1e-3);  // a real nutation, not a steady precession
  RecordProperty("theta1", sci(theta1));
  RecordProperty("max_tilt_error", sci(std::abs(hi - theta1)));
  RecordProperty("min_tilt_error", sci(std::abs(lo - theta0)));
}

TEST(SpatialBushing, MountedBodyOscillatesAtTheClosedFormFrequencies) {
  // A body on a bushing to the ground, no gravity: along z the mount is a linear spring,
  // z(t) = (v0 / w) sin(w t), w = sqrt(kz / m); about z a torsion spring of measure
  // sin(theta) (to second order theta), so for a 1e-4 rad amplitude
  // theta(t) = (w0 / W) sin(W t), W = sqrt(krz / Izz), to ~1e-8 relative.
  constexpr double m = 2.0, Izz = 0.05, kz = 800.0, krz = 20.0, v0 = 0.01, w0 = 1e-3;
  System sys;
  RigidBody3dProperties p;
  p.mass = m;
  p.inertia = Vec3(0.04, 0.045, Izz).asDiagonal();
  FrameState3d s0;
  s0.velocity = Vec3(0.0, 0.0, v0);
  s0.angularVelocity = Vec3(0.0, 0.0, w0);
  const BodyIndex b = sys.addBody(std::make_unique<RigidBody3d>("mass", p, s0));
  sys.addForce(std::make_unique<SpatialBushing>("mount", kGround, JointFrame{}, b, JointFrame{},
                                                std::array<double, 6>{500.0, 600.0, kz, 30.0, 40.0, krz},
                                                std::array<double, 6>{}));
  sys.finalize();
  const double w = std::sqrt(kz / m), W = std::sqrt(krz / Izz);
  double ez = 0.0, et = 0.0;
  const SimulationSummary s = simulate(sys, settings(1.0, 1e-10, 0.005), [&](const OutputSample& o) {
    ez = std::max(ez, std::abs(o.q[2] - v0 / w * std::sin(w * o.t)));
    const Mat3 A = RigidBody3d::rotationOf(o.q.segment(sys.coordinateOffset(b), 7));
    et = std::max(et, std::abs(std::atan2(A(1, 0), A(0, 0)) - w0 / W * std::sin(W * o.t)));
  });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_LE(ez, 1e-6 * v0 / w);
  EXPECT_LE(et, 1e-6 * w0 / W);
  RecordProperty("z_error_relative", sci(ez / (v0 / w)));
  RecordProperty("angle_error_relative", sci(et / (w0 / W)));
}
