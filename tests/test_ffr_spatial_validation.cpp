// Validation of spatial flexible bodies (C++ API): FfrBody3d from FfrBeamModel3d
// in mechanisms.
//  1. The planar elastic slider crank (examples/slider_crank_elastic.json: nodal 8
//     elements and 2 modes) rebuilt in space in the x-y plane against the planar engine:
//     the equations at the same states to round-off, and the runs at the example's solver
//     settings (and tighter) to the integration error.
//  2. A spatial slider crank with the crank axis inclined to the slider's line and a
//     flexible connecting rod (spherical + universal joints): energy conserved with a free
//     crank; with a driver, the driver's work equals the change of energy; with E x 1e3
//     the rod's frame and the slider follow the rigid model (RigidBody3d rod).
//  3. Geometric stiffening in space: a cantilever clamped to a hub spinning at Omega about
//     an axis perpendicular to it; first flapwise and chordwise frequencies measured from
//     the time response (zero crossings) against the Southwell relation and the
//     linearisation of the body's own equations.
// Longer variants (nodal rods, E x 1e4, more spin speeds and periods): label slow, the
// binary test_ffr_spatial_validation_slow (this source with FLEXMBD_SPATIAL_VALIDATION_SLOW).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <complex>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"
#include "problems/ffr3d_crank_models.hpp"
#include "problems/ffr_test_models.hpp"

using namespace flexmbd;
using namespace flexmbd::test3d;

namespace {

Vec4 quaternionZ(double theta) { return Vec4(std::cos(theta / 2), 0.0, 0.0, std::sin(theta / 2)); }
Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

// =====================================================================================
// 1. The planar elastic slider crank in space
// =====================================================================================

/// The map of the planar model's states (q, v, a) onto the spatial one's.
struct PlanarToSpatial {
  const Scene* planar = nullptr;
  const ElasticCrank3d* spatial = nullptr;
  BodyIndex crank2, rod2, slider2;
  MatX P;                    // q_f (3D) = P q_f (planar)
  double shapeResidual = 0;  // |B3_in-plane P - B2| / |B2|: the elastic fields agree
  int nf2 = 0, nf3 = 0;

  PlanarToSpatial(const Scene& s2, const ElasticCrank3d& s3) : planar(&s2), spatial(&s3) {
    const System& sys = s2.system;
    crank2 = sys.findBody("crank");
    rod2 = sys.findBody("rod");
    slider2 = sys.findBody("slider");
    const auto& rod = dynamic_cast<const FfrBody2d&>(sys.body(rod2));
    const MatX B2(rod.beamModel()->basis());
    const MatX B3(s3.model->basis());
    const int nodes = static_cast<int>(B2.rows()) / 3;
    MatX B3in(3 * nodes, B3.cols());
    const int map[3] = {0, 1, 5};  // (ux, uy, psi) -> (ux, uy, thz)
    for (int n = 0; n < nodes; ++n)
      for (int k = 0; k < 3; ++k) B3in.row(3 * n + k) = B3.row(6 * n + map[k]);
    // least squares, minimum norm: the out-of-plane columns (zero in-plane rows) get zero
    P = B3in.completeOrthogonalDecomposition().solve(B2);
    shapeResidual = (B3in * P - B2).norm() / B2.norm();
    nf2 = static_cast<int>(B2.cols());
    nf3 = static_cast<int>(B3.cols());
  }

  /// Velocity-space map of a planar vector (v or a; `acceleration` adds the crank's
  /// centripetal term). The crank's 3D reference point is its centre of mass.
  void velocities(const VecX& q2, const VecX& v2, const VecX* a2, VecX& out) const {
    const System& s2 = planar->system;
    const System& s3 = spatial->sys;
    out = VecX::Zero(s3.numVelocities());
    const VecX& x = a2 ? *a2 : v2;
    const Vec2 c(0.075, 0.0);
    {
      const int oq = s2.coordinateOffset(crank2), ov = s2.velocityOffset(crank2), o3 = s3.velocityOffset(spatial->crank);
      const double th = q2[oq + 2], w = v2[ov + 2];
      const Vec2 rc = rotation(th) * c, perp(-rc.y(), rc.x());
      Vec2 lin = x.segment<2>(ov) + x[ov + 2] * perp;
      if (a2) lin -= w * w * rc;
      out.segment<2>(o3) = lin;
      out[o3 + 5] = x[ov + 2];
    }
    for (BodyIndex b2 : {rod2, slider2}) {
      const BodyIndex b3 = b2 == rod2 ? spatial->rod : spatial->slider;
      const int ov = s2.velocityOffset(b2), o3 = s3.velocityOffset(b3);
      out.segment<2>(o3) = x.segment<2>(ov);
      out[o3 + 5] = x[ov + 2];
    }
    const int ov = s2.velocityOffset(rod2) + 3, o3 = s3.velocityOffset(spatial->rod) + 6;
    out.segment(o3, nf3) = P * x.segment(ov, nf2);
  }

  void coordinates(const VecX& q2, VecX& q3) const {
    const System& s2 = planar->system;
    const System& s3 = spatial->sys;
    q3 = VecX::Zero(s3.numCoordinates());
    {
      const int oq = s2.coordinateOffset(crank2), o3 = s3.coordinateOffset(spatial->crank);
      const double th = q2[oq + 2];
      q3.segment<2>(o3) = q2.segment<2>(oq) + rotation(th) * Vec2(0.075, 0.0);
      q3.segment<4>(o3 + 3) = quaternionZ(th);
    }
    for (BodyIndex b2 : {rod2, slider2}) {
      const BodyIndex b3 = b2 == rod2 ? spatial->rod : spatial->slider;
      const int oq = s2.coordinateOffset(b2), o3 = s3.coordinateOffset(b3);
      q3.segment<2>(o3) = q2.segment<2>(oq);
      q3.segment<4>(o3 + 3) = quaternionZ(q2[oq + 2]);
    }
    const int oq = s2.coordinateOffset(rod2) + 3, o3 = s3.coordinateOffset(spatial->rod) + 7;
    q3.segment(o3, nf3) = P * q2.segment(oq, nf2);
  }
};

struct ReproductionFigures {
  double shape = 0;         // mode / basis agreement
  double acceleration = 0;  // max |a3 - map(a2)| / max |map(a2)| over the states
  double torque = 0;        // max |tau3 - tau2| / max |tau2|
  double outOfPlane = 0;    // max |a3| on the out-of-plane velocities / max |a|
  // runs at the same settings
  double slider = 0, deflection = 0, elastic = 0, peakDeflection = 0, maxOutOfPlane = 0;
  long steps2 = 0, steps3 = 0;
  double cpu2 = 0, cpu3 = 0;
  bool ok = false;
};

/// Both models at rtol (the example's settings: 1e-6, atol 1e-8, one revolution, its
/// output step), with the equations compared at every planar output state.
ReproductionFigures reproduce(int modes, bool planarInertia, double rtol, double atol, double revolutions = 1.0) {
  ReproductionFigures f;
  Scene s2 = testmodels::elasticSliderCrank(8, 1.0, modes, revolutions, rtol, atol);
  // the models are compared, so both run on the same integrator ("auto" would give the
  // planar nodal rod radau5 and the spatial one, which has no modal analysis, IDA)
  s2.solver.integrator = IntegratorKind::Ida;
  const auto c3 = planarElasticCrank3d(planarCrankRod3d(8, modes), planarInertia);
  const System& sys3 = c3->sys;
  const PlanarToSpatial map(s2, *c3);
  f.shape = map.shapeResidual;
  const int x2 = s2.system.coordinateOffset(map.slider2), x3 = sys3.coordinateOffset(c3->slider);
  const int f2 = s2.system.coordinateOffset(map.rod2) + 3, f3 = sys3.coordinateOffset(c3->rod) + 7;
  const int m2 = s2.system.constraintOffset(s2.system.findConstraint("motor")), m3 = sys3.constraintOffset(c3->motor);
  const auto& B2 = dynamic_cast<const FfrBody2d&>(s2.system.body(map.rod2)).beamModel()->basis();
  const auto& B3 = c3->model->basis();
  const int mid = c3->midNode;
  std::vector<OutputSample> run2, run3;
  const SimulationSummary r2 = simulate(s2.system, s2.solver, [&](const OutputSample& o) { run2.push_back(o); });
  const SimulationSummary r3 = simulate(sys3, s2.solver, [&](const OutputSample& o) { run3.push_back(o); });
  f.ok = r2.ok && r3.ok && run2.size() == run3.size();
  if (!f.ok) {
    ADD_FAILURE() << r2.message << " / " << r3.message << " (" << run2.size() << " and " << run3.size() << " outputs)";
    return f;
  }
  f.steps2 = r2.stats.steps;
  f.steps3 = r3.stats.steps;
  f.cpu2 = r2.cpuSeconds;
  f.cpu3 = r3.cpuSeconds;
  double aScale = 0, aErr = 0, tScale = 0, tErr = 0, oop = 0;
  double eScale = 0;
  for (size_t k = 0; k < run2.size(); ++k) {
    const OutputSample& o2 = run2[k];
    const OutputSample& o3 = run3[k];
    // (a) the equations at the planar state, mapped: accelerations and motor torque
    VecX a2, l2, q3, v3, a3, l3, a2m;
    computeAccelerations(s2.system, o2.t, o2.q, o2.v, a2, l2);
    map.coordinates(o2.q, q3);
    map.velocities(o2.q, o2.v, nullptr, v3);
    computeAccelerations(sys3, o2.t, q3, v3, a3, l3);
    map.velocities(o2.q, o2.v, &a2, a2m);
    aScale = std::max(aScale, a2m.lpNorm<Eigen::Infinity>());
    VecX d = a3 - a2m;
    aErr = std::max(aErr, d.lpNorm<Eigen::Infinity>());
    tScale = std::max(tScale, std::abs(l2[m2]));
    tErr = std::max(tErr, std::abs(l3[m3] - l2[m2]));
    // out of the plane: z, wx, wy of each body and the rod's nodal uz, thx, thy
    for (BodyIndex b : {c3->crank, c3->rod, c3->slider}) {
      const int o = sys3.velocityOffset(b);
      oop = std::max({oop, std::abs(a3[o + 2]), std::abs(a3[o + 3]), std::abs(a3[o + 4])});
    }
    const VecX un = B3 * a3.segment(sys3.velocityOffset(c3->rod) + 6, map.nf3);
    for (int n = 0; n < un.size() / 6; ++n) oop = std::max({oop, std::abs(un[6 * n + 2]), std::abs(un[6 * n + 3]), std::abs(un[6 * n + 4])});
    // (b) the runs at the same settings
    const VecX u2 = B2 * o2.q.segment(f2, map.nf2), u3 = B3 * o3.q.segment(f3, map.nf3);
    const double y2 = u2[3 * mid + 1], y3 = u3[6 * mid + 1];
    f.peakDeflection = std::max(f.peakDeflection, std::abs(y2));
    f.deflection = std::max(f.deflection, std::abs(y3 - y2));
    f.slider = std::max(f.slider, std::abs(o3.q[x3] - o2.q[x2]));
    const VecX qf3in = map.P * o2.q.segment(f2, map.nf2);
    f.elastic = std::max(f.elastic, (o3.q.segment(f3, map.nf3) - qf3in).lpNorm<Eigen::Infinity>());
    eScale = std::max(eScale, qf3in.lpNorm<Eigen::Infinity>());
    for (int n = 0; n < u3.size() / 6; ++n) f.maxOutOfPlane = std::max(f.maxOutOfPlane, std::abs(u3[6 * n + 2]));
    for (BodyIndex b : {c3->crank, c3->rod, c3->slider}) f.maxOutOfPlane = std::max(f.maxOutOfPlane, std::abs(o3.q[sys3.coordinateOffset(b) + 2]));
  }
  f.acceleration = aErr / aScale;
  f.torque = tErr / tScale;
  f.outOfPlane = oop / aScale;
  f.elastic /= eScale;
  return f;
}

}  // namespace

#ifndef FLEXMBD_SPATIAL_VALIDATION_SLOW

TEST(SpatialFlexibleInPlane, ElasticSliderCrankGivesThePlanarResults) {
  // Tolerances.
  //  - kRoundOff: the same equations at the same state, assembled by other code (3D
  //    invariants, quaternions, spatial joints) and solved by another factorisation: the
  //    accelerations carry round-off of the elastic forces, K_ff q_f ~ 1e11 x 1e-3, over
  //    the largest acceleration ~1e4: eps * cond ~ 1e-16 x 1e6; bound 1e-9 relative.
  //  - The runs: the two integrations take different steps (other unknowns, other error
  //    norms), so they agree to the integration error, not to round-off: at the example's
  //    rtol 1e-6 the slider to kSliderRun (measured 2.6e-10 m nodal, 6.2e-9 m modal; the
  //    slider moves 0.3 m), the midpoint deflection (~2 mm) to kDeflectionRun of its peak
  //    (measured 7.6e-8 nodal, 5.0e-6 modal).
  //  - Out of the plane, nothing is excited: the out-of-plane accelerations at in-plane
  //    states are round-off (kRoundOff of the scale), the coordinates stay at round-off
  //    level through the runs (kOutOfPlane, m).
  //  - The in-plane elastic coordinates (3D q_f against P q_f of the planar run, P the map
  //    of the in-plane nodal fields): integration error too, kElasticRun of their largest
  //    value (measured 1.2e-6 nodal, 7.3e-6 modal).
  constexpr double kRoundOff = 1e-9, kSliderRun = 1e-7, kDeflectionRun = 1e-4, kElasticRun = 1e-4, kOutOfPlane = 1e-12;
  for (int modes : {0, 2}) {
    const ReproductionFigures f = reproduce(modes, true, 1e-6, 1e-8);
    ASSERT_TRUE(f.ok);
    const char* what = modes ? "2 modes" : "8 nodal elements";
    std::printf("[ figures ] in plane, %s: elastic fields (B3 P vs B2) %.1e; equations at the %s states: accelerations "
                "%.1e, motor torque %.1e, out-of-plane accelerations %.1e (relative)\n",
                what, f.shape, what, f.acceleration, f.torque, f.outOfPlane);
    std::printf("[ figures ] in plane, %s, rtol 1e-6 (the example): |dx slider| %.2e m, |d mid deflection| %.2e m "
                "(%.1e of the peak %.3e m), in-plane q_f %.1e (relative), max out-of-plane %.1e m; steps %ld planar, %ld "
                "spatial; CPU %.3f s planar, %.3f s spatial\n",
                what, f.slider, f.deflection, f.deflection / f.peakDeflection, f.peakDeflection, f.elastic,
                f.maxOutOfPlane, f.steps2, f.steps3, f.cpu2, f.cpu3);
    EXPECT_LT(f.shape, kRoundOff);
    EXPECT_LT(f.acceleration, kRoundOff);
    EXPECT_LT(f.torque, kRoundOff);
    EXPECT_LT(f.outOfPlane, kRoundOff);
    EXPECT_LT(f.slider, kSliderRun);
    EXPECT_LT(f.deflection, kDeflectionRun * f.peakDeflection);
    EXPECT_LT(f.elastic, kElasticRun);
    EXPECT_LT(f.maxOutOfPlane, kOutOfPlane);
  }
}

TEST(SpatialFlexibleInPlane, RunsConvergeToEachOtherWithTheTolerance) {
  // The difference of the runs is integration error: 2 modes at rtol 1e-6, 1e-8, 1e-10
  // (atol = rtol / 100); it falls with the tolerance, to kTight at rtol 1e-10.
  constexpr double kTightSlider = 1e-9, kTightDeflection = 1e-6;  // m; relative to the peak
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-8, 1e-10}) {
    const ReproductionFigures f = reproduce(2, true, rtol, rtol * 1e-2);
    ASSERT_TRUE(f.ok);
    std::printf("[ figures ] in plane, 2 modes, rtol %.0e: |dx slider| %.2e m, |d mid deflection| %.2e of the peak, "
                "in-plane q_f %.1e\n", rtol, f.slider, f.deflection / f.peakDeflection, f.elastic);
    EXPECT_LT(f.slider, previous);
    previous = f.slider;
    if (rtol == 1e-10) {
      EXPECT_LT(f.slider, kTightSlider);
      EXPECT_LT(f.deflection, kTightDeflection * f.peakDeflection);
    }
  }
}

TEST(SpatialFlexibleInPlane, SectionRotaryInertiaIsTheOnlyDifferenceOfTheBeamModelBody) {
  // The body made from FfrBeamModel3d as it is keeps the section's rotary inertia in the
  // plane, rho Iz L = 3 Iz / (A L^2) = 1.8e-4 of the rod's moment of inertia about its
  // end, which the planar element leaves out. The crank is driven and the rigid motion is
  // fixed by the joints, and that term (in the frame's rotational inertia only, not in
  // the frame-elastic coupling) does not enter the elastic equations: the accelerations
  // stay equal to round-off (kRoundOff), the motor torque carries the extra inertia
  // torque rho Iz L theta_rod'' (between kSectionTermLow and kSectionTermHigh of the
  // largest torque).
  constexpr double kRoundOff = 1e-9, kSectionTermLow = 1e-6, kSectionTermHigh = 1e-3;
  const ReproductionFigures f = reproduce(2, false, 1e-6, 1e-8);
  ASSERT_TRUE(f.ok);
  std::printf("[ figures ] in plane, 2 modes, FfrBody3d(model) with the section's rho Iz L: accelerations %.2e, motor "
              "torque %.2e (relative); run: |d mid deflection| %.2e of the peak\n",
              f.acceleration, f.torque, f.deflection / f.peakDeflection);
  EXPECT_LT(f.acceleration, kRoundOff);
  EXPECT_GT(f.torque, kSectionTermLow);
  EXPECT_LT(f.torque, kSectionTermHigh);
}

#endif

// =====================================================================================
// 2. A spatial slider crank with a flexible rod
// =====================================================================================

namespace {

/// Crank of radius r about an axis n tilted by alpha from world z (about world y),
/// through the origin; slider on the line (s, e, h) along world x; connecting rod of
/// length L on a spherical joint at the crank pin and a universal joint at the slider.
/// DOF: 3 bodies x 6 - (revolute 5 + spherical 3 + universal 4 + prismatic 5) = 1 (the
/// crank angle), plus the rod's elastic coordinates; the universal joint (the slider's
/// arm along world y, the rod's along its body z, perpendicular to the rod and to world
/// y) locks the rod's spin about its own axis. Gravity along -z.
struct InclinedCrank {
  static constexpr double r = 0.08, L = 0.30, e = 0.03, h = 0.05, alpha = M_PI / 6, th0 = 0.4;
  System sys;
  BodyIndex crank, rod, slider;
  ConstraintIndex motor{-1};
  std::shared_ptr<const FfrBeamModel3d> model;
  const FfrBody3d* flex = nullptr;  // or
  Vec3 rigidCom;                    // the rigid rod's centre of mass in the rod frame (origin at the pin)
  bool driven = false;
  TimeLawPtr law;
};

/// flexible: FfrBody3d of `N` elements (pinned-pinned; `modes` > 0: its first modes, 0:
/// nodal) with E x eScale; else the RigidBody3d with the same mass and inertia. driveSpeed > 0: a spin-up driver to that
/// speed over `ramp` s; else a free crank started at `omega0`.
std::unique_ptr<InclinedCrank> inclinedCrank(bool flexible, double eScale, int N, int modes, double driveSpeed,
                                             double ramp, double omega0) {
  using C = InclinedCrank;
  auto c = std::make_unique<InclinedCrank>();
  System& sys = c->sys;
  sys.setGravity(Vec3(0.0, 0.0, -9.81));
  const Mat3 bearing = rotY(C::alpha);
  // crank: body x along the arm, z along the axis; centre of mass at mid-arm
  FrameState3d cs;
  cs.orientation = bearing * rotZ(C::th0);
  cs.position = cs.orientation * Vec3(C::r / 2, 0, 0);
  cs.angularVelocity = Vec3(0, 0, driveSpeed > 0 ? 0.0 : omega0);
  cs.velocity = cs.orientation * cs.angularVelocity.cross(Vec3(C::r / 2, 0, 0));
  RigidBody3dProperties pc;
  pc.mass = 0.2;
  pc.inertia = Vec3(1e-5, 0.2 * C::r * C::r / 12 + 1e-5, 0.2 * C::r * C::r / 12).asDiagonal();
  c->crank = sys.addBody(std::make_unique<RigidBody3d>("crank", pc, cs));
  const Vec3 P = cs.orientation * Vec3(C::r, 0, 0);
  const double s = P.x() + std::sqrt(C::L * C::L - std::pow(C::e - P.y(), 2) - std::pow(C::h - P.z(), 2));
  const Vec3 S(s, C::e, C::h);
  const Vec3 d = (S - P) / C::L, z = d.cross(Vec3::UnitY()).normalized();
  FrameState3d rs;
  rs.orientation.col(0) = d;
  rs.orientation.col(1) = z.cross(d);
  rs.orientation.col(2) = z;
  rs.position = P;
  // the rod: steel 8 mm x 8 mm, 0.3 m, pinned-pinned (chord frame)
  BeamSection3d sec = rectangularSection3d(0.008, 0.008, 2e11 * eScale, 2e11 * eScale / 2.6, 7870.0, 0.0);
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::PinnedPinned;
  o.modes = modes;
  c->model = std::make_shared<const FfrBeamModel3d>(BeamMesh3d::straight(C::L, N, sec), o, "body 'rod'");
  JointFrame rodStart, rodEnd;
  rodEnd.point = Vec3(C::L, 0, 0);
  if (flexible) {
    auto rod = std::make_unique<FfrBody3d>("rod", c->model, rs);
    c->flex = rod.get();
    c->rod = sys.addBody(std::move(rod));
  } else {
    const FfrInvariants3d& inv = c->model->invariants();
    const Vec3 com = inv.firstMoment / inv.mass;
    const Mat3 J0 = inv.secondMoment - inv.mass * com * com.transpose();
    RigidBody3dProperties pr;
    pr.mass = inv.mass;
    pr.inertia = J0.trace() * Mat3::Identity() - J0;
    FrameState3d rr = rs;
    rr.position = P + rs.orientation * com;
    c->rigidCom = com;
    rodStart.point = -com;
    rodEnd.point -= com;
    c->rod = sys.addBody(std::make_unique<RigidBody3d>("rod", pr, rr));
  }
  FrameState3d ss;
  ss.position = S;
  RigidBody3dProperties ps;
  ps.mass = 0.1;
  ps.inertia = Vec3(2e-5, 2e-5, 2e-5).asDiagonal();
  c->slider = sys.addBody(std::make_unique<RigidBody3d>("slider", ps, ss));
  JointFrame ground, crankAxis, crankPin, sliderCross, rail, railOnSlider;
  ground.axes = bearing;
  crankAxis.point = Vec3(-C::r / 2, 0, 0);
  crankPin.point = Vec3(C::r / 2, 0, 0);
  sliderCross.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // x along world y
  rodEnd.axes.col(0) = Vec3::UnitY();
  rodEnd.axes.col(1) = Vec3::UnitZ();  // the rod's arm: its body z
  rodEnd.axes.col(2) = Vec3::UnitX();
  rail.axes = rodEnd.axes;  // z along world x
  rail.point = Vec3(0, C::e, C::h);
  railOnSlider.axes = rail.axes;
  sys.addConstraint(std::make_unique<SpatialJoint>("bearing", SpatialJointType::Revolute, kGround, ground, c->crank, crankAxis));
  sys.addConstraint(std::make_unique<SpatialJoint>("pin", SpatialJointType::Spherical, c->crank, crankPin, c->rod, rodStart));
  sys.addConstraint(std::make_unique<SpatialJoint>("cardan", SpatialJointType::Universal, c->slider, sliderCross, c->rod, rodEnd));
  sys.addConstraint(std::make_unique<SpatialJoint>("rail", SpatialJointType::Prismatic, kGround, rail, c->slider, railOnSlider));
  if (driveSpeed > 0) {
    c->driven = true;
    c->law = makeSpinUpLaw(driveSpeed, ramp, C::th0);
    c->motor = sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, ground, c->crank, crankAxis, c->law));
  }
  sys.finalize();
  return c;
}

SolverSettings settingsFor(double tEnd, double rtol, double outputStep) {
  SolverSettings st;
  st.rtol = rtol;
  st.atol = rtol * 1e-2;
  st.tEnd = tEnd;
  st.outputStep = outputStep;
  st.progress = false;
  return st;
}

/// Total energy 1/2 v^T M v + strain + gravity.
double totalEnergy(const System& sys, const VecX& q, const VecX& v) { return kineticEnergy(sys, q, v) + potentialEnergy(sys, q); }

}  // namespace

namespace {

struct EnergyRun {
  double drift = 0, T0 = 0, peakStrain = 0, minSpeed = INFINITY;
  SimulationSummary summary;
};

/// Free crank started at 60 rad/s (the initialisation makes the velocities consistent),
/// gravity, no damping, 0.1 s (about one revolution, ~20 periods of the rod's first
/// bending mode): the largest |E - E0| of the total energy (kinetic + strain + gravity).
EnergyRun freeCrankEnergy(int N, int modes, double rtol) {
  EnergyRun r;
  const auto c = inclinedCrank(true, 1.0, N, modes, 0.0, 0.0, 60.0);
  double E0 = NAN;
  const int wc = c->sys.velocityOffset(c->crank) + 5, oq = c->sys.coordinateOffset(c->rod);
  r.summary = simulate(c->sys, settingsFor(0.1, rtol, 1e-3), [&](const OutputSample& o) {
    const double E = totalEnergy(c->sys, o.q, o.v);
    if (std::isnan(E0)) {
      E0 = E;
      r.T0 = kineticEnergy(c->sys, o.q, o.v);
    }
    r.drift = std::max(r.drift, std::abs(E - E0));
    r.peakStrain = std::max(r.peakStrain, c->flex->internalPotential(o.q.segment(oq, c->flex->numCoordinates())));
    r.minSpeed = std::min(r.minSpeed, o.v[wc]);
  });
  std::printf("[ figures ] inclined crank, free, %s, 0.1 s at rtol %.0e: energy drift %.2e of the kinetic energy %.4f J "
              "(peak strain energy %.2e J, slowest crank %.1f rad/s), %ld steps, %.2f s CPU\n",
              modes ? (std::to_string(N) + " elements, " + std::to_string(modes) + " modes").c_str()
                    : (std::to_string(N) + " nodal elements").c_str(),
              rtol, r.drift / r.T0, r.T0, r.peakStrain, r.minSpeed, r.summary.stats.steps, r.summary.cpuSeconds);
  return r;
}

struct WorkRun {
  double work = 0, dE = 0, worst = 0, scale = 0;
  SimulationSummary summary;
};

/// The crank spun up from rest to 100 rad/s over 0.05 s (the smooth spin-up law), then
/// held, to 0.1 s; gravity, no damping. The driver's power is -lambda theta'(t) (lambda
/// its multiplier: the torque it applies is -lambda), its work by Simpson's rule over
/// outputs every h; compared with the change of the total energy at every other output.
WorkRun driverWork(int N, int modes, double rtol, double h) {
  WorkRun r;
  const auto c = inclinedCrank(true, 1.0, N, modes, 100.0, 0.05, 0.0);
  const int m = c->sys.constraintOffset(c->motor);
  std::vector<double> power, energy;
  r.summary = simulate(c->sys, settingsFor(0.1, rtol, h), [&](const OutputSample& o) {
    power.push_back(-o.lambda[m] * c->law->evaluate(o.t).df);
    energy.push_back(totalEnergy(c->sys, o.q, o.v));
  });
  if (!r.summary.ok) return r;
  for (size_t k = 2; k < power.size(); k += 2) {
    r.work += h / 3 * (power[k - 2] + 4 * power[k - 1] + power[k]);
    r.dE = energy[k] - energy[0];
    r.worst = std::max(r.worst, std::abs(r.work - r.dE));
    r.scale = std::max(r.scale, std::abs(r.dE));
  }
  std::printf("[ figures ] inclined crank, driven (spin-up to 100 rad/s), %s, rtol %.0e: driver work %.7f J, energy "
              "change %.7f J, largest |W - dE| over the run %.2e J (%.1e relative), %ld steps, %.2f s CPU\n",
              modes ? (std::to_string(N) + " elements, " + std::to_string(modes) + " modes").c_str()
                    : (std::to_string(N) + " nodal elements").c_str(),
              rtol, r.work, r.dE, r.worst, r.worst / r.scale, r.summary.stats.steps, r.summary.cpuSeconds);
  return r;
}

}  // namespace

namespace {

struct RigidLimit {
  double frame = 0, rotation = 0, slider = 0, deflection = 0;
  long steps = 0;
  double cpu = 0;
  bool ok = false;
};

/// The flexible rod (E x eScale) against the rigid rod, the crank driven by the same
/// spin-up law (0 to 150 rad/s over 0.04 s, then held, to 0.08 s): largest differences of
/// the rod's frame origin (the pin; the rigid rod's centre of mass less A c), of its
/// orientation (|A_flex - A_rigid|, Frobenius, ~ the angle between them), of the slider,
/// and the peak transverse deflection of the flexible rod's midpoint.
RigidLimit rigidLimit(double eScale, int N, int modes, double rtol) {
  RigidLimit out;
  const auto f = inclinedCrank(true, eScale, N, modes, 150.0, 0.04, 0.0);
  const auto r = inclinedCrank(false, eScale, N, modes, 150.0, 0.04, 0.0);
  const SolverSettings st = settingsFor(0.08, rtol, 5e-4);
  std::vector<OutputSample> sf, sr;
  const SimulationSummary a = simulate(f->sys, st, [&](const OutputSample& o) { sf.push_back(o); });
  const SimulationSummary b = simulate(r->sys, st, [&](const OutputSample& o) { sr.push_back(o); });
  out.ok = a.ok && b.ok && sf.size() == sr.size();
  if (!out.ok) {
    ADD_FAILURE() << a.message << " / " << b.message;
    return out;
  }
  out.steps = a.stats.steps;
  out.cpu = a.cpuSeconds;
  const int of = f->sys.coordinateOffset(f->rod), orr = r->sys.coordinateOffset(r->rod);
  const int xf = f->sys.coordinateOffset(f->slider), xr = r->sys.coordinateOffset(r->slider);
  const int nf = f->flex->numElastic();
  const FfrPoint3d& mid = f->flex->invariants().points[f->flex->resolvePoint(Vec3(InclinedCrank::L / 2, 0, 0), "test")];
  for (size_t k = 0; k < sf.size(); ++k) {
    const VecX qf = sf[k].q.segment(of, 7 + nf), qr = sr[k].q.segment(orr, 7);
    const Mat3 Af = FfrBody3d::rotationOf(qf), Ar = RigidBody3d::rotationOf(qr);
    out.frame = std::max(out.frame, (qf.head<3>() - (qr.head<3>() - Ar * r->rigidCom)).norm());
    out.rotation = std::max(out.rotation, (Af - Ar).norm());
    out.slider = std::max(out.slider, std::abs(sf[k].q[xf] - sr[k].q[xr]));
    const Vec3 u = mid.shape * qf.tail(nf);
    out.deflection = std::max(out.deflection, std::hypot(u.y(), u.z()));
  }
  std::printf("[ figures ] inclined crank, E x %.0e, %d elements%s, rtol %.0e: flexible vs rigid rod: frame origin %.2e m, "
              "orientation %.2e, slider %.2e m; peak midpoint deflection %.3e m; %ld steps, %.2f s CPU\n",
              eScale, N, modes ? (", " + std::to_string(modes) + " modes").c_str() : " nodal", rtol, out.frame,
              out.rotation, out.slider, out.deflection, out.steps, out.cpu);
  return out;
}

}  // namespace

#ifndef FLEXMBD_SPATIAL_VALIDATION_SLOW

TEST(SpatialFlexibleCrank, FreeCrankConservesEnergy) {
  // 8 elements reduced to 4 modes (the first two bending modes in each plane; nodal
  // 4 elements: the slow variant). Energy is conserved to the integrator's error: BDF at
  // rtol 1e-9 loses ~1e-7 per period of the vibration's share of the energy
  // (test_ffr_validation, free-floating beam) and the rigid motion's error is ~rtol per
  // revolution; bound kEnergyDrift relative to the kinetic energy.
  constexpr double kEnergyDrift = 1e-6;
  const EnergyRun r = freeCrankEnergy(8, 4, 1e-9);
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  EXPECT_LT(r.drift, kEnergyDrift * r.T0);
  EXPECT_GT(r.peakStrain, 1e-6 * r.T0);  // the rod does deform
}

TEST(SpatialFlexibleCrank, DriverWorkEqualsTheChangeOfEnergy) {
  // 8 elements, 4 modes (highest ~5000 rad/s), outputs every h = 1e-5 s: Simpson's
  // error is (h w)^4 / 180 ~ 1e-11 of the vibration's power and (h / 0.05 s)^4 of the
  // slow part; with the integration error at rtol 1e-9 (~1e-8 of the energy), the
  // balance holds to kWorkBalance of the energy change (measured 3.7e-7).
  constexpr double kWorkBalance = 2e-6;
  const WorkRun r = driverWork(8, 4, 1e-9, 1e-5);
  ASSERT_TRUE(r.summary.ok) << r.summary.message;
  EXPECT_LT(r.worst, kWorkBalance * r.scale);
}

TEST(SpatialFlexibleCrank, StiffRodFollowsTheRigidRod) {
  // 8 elements, 4 modes (bending, both planes), at E x 1 and E x 1e3, rtol 1e-8.
  //  - Frame origin (the pin) and slider: the modes keep the chord's length (no axial
  //    mode), so the pinned-pinned chord frame moves as the rigid rod does and the
  //    positions differ by the integration error only (~rtol x 0.3 m): kPosition. With
  //    the axial field (nodal, the slow variant) the chord stretches by F L / (E A) ~ 5e-9 m
  //    at E x 1 (F ~ 200 N), 5e-12 m at E x 1e3.
  //  - Orientation: the universal joint holds the rod's cross arm at the far node, whose
  //    section turns with the bending slope there, so the frame's spin about the rod axis
  //    differs from the rigid one by that slope, ~deflection / L: elastic, 1/E. Measured
  //    2.1e-3 at E x 1: kOrientation at E x 1e3 (2.1e-6 expected).
  //  - The elastic deformation scales as 1/E: the peak midpoint deflection falls by 1e3
  //    up to the dynamic amplification 1/(1 - (k w / omega_1)^2) of the crank's harmonics
  //    k w (w = 150 rad/s, omega_1 ~ 1280 rad/s at E x 1: 1.4 % for k = 1, 6 % for
  //    k = 2, gone at E x 1e3) and the start-up vibration: kScaling.
  constexpr double kPosition = 1e-8, kOrientation = 1e-5, kScaling = 0.15;
  const RigidLimit r1 = rigidLimit(1.0, 8, 4, 1e-8), r3 = rigidLimit(1e3, 8, 4, 1e-8);
  ASSERT_TRUE(r1.ok && r3.ok);
  EXPECT_LT(r3.frame, kPosition);
  EXPECT_LT(r3.slider, kPosition);
  EXPECT_LT(r3.rotation, kOrientation);
  EXPECT_NEAR(r1.deflection / r3.deflection, 1e3, 1e3 * kScaling);
  EXPECT_NEAR(r1.rotation / r3.rotation, 1e3, 1e3 * kScaling);
  std::printf("[ figures ] rigid limit: deflection ratio E x 1 / E x 1e3 %.1f, orientation-difference ratio %.1f\n",
              r1.deflection / r3.deflection, r1.rotation / r3.rotation);
}

#endif

// =====================================================================================
// 3. Geometric stiffening in space: the spinning cantilever
// =====================================================================================

namespace {

/// Uniform cantilever, L = 1, rho A = 1, EA = 1e4 (slender): flapwise (bending out of the
/// plane of rotation, about the section's y axis) EIy = 1, omega0 = 1.8751^2 = 3.516
/// rad/s; chordwise (in the plane of rotation) EIz = 4, omega0 = 7.03 rad/s (apart from
/// the flapwise one); GJ = 0.8. Clamped at node 0 to the frame, whose origin sits on the
/// spin axis: a revolute joint about world z at node 0 and an angle driver at constant
/// speed Omega (the hub). 8 nodal elements.
std::shared_ptr<const FfrBeamModel3d> bladeModel(bool stiffening, int N = 8) {
  BeamSection3d s;
  s.area = 1.0;
  s.inertiaY = 1e-4;
  s.inertiaZ = 4e-4;
  s.torsionConstant = 2e-4;
  s.youngsModulus = 1e4;
  s.shearModulus = 4e3;
  s.density = 1.0;
  s.damping = 1e-3;  // light Rayleigh damping (see the tolerances below)
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  o.geometricStiffening = stiffening;
  return std::make_shared<const FfrBeamModel3d>(BeamMesh3d::straight(1.0, N, s), o, "body 'blade'");
}

/// The linearisation of the blade's elastic equations about its relative equilibrium at
/// spin Omega: the frame's motion is prescribed (R'' = 0, w' = 0), so m_ff q'' = Q_f(q, q')
/// with Q_f the body's own internal forces (elastic, from the strain energy, and quadratic
/// velocity forces at w = Omega e_z): Q_f(q_eq) = 0 by Newton, then K = dQ_f/dq_f,
/// G = dQ_f/dq_f'. Modes: the lowest flapwise (tip motion along z) and chordwise (along y).
struct SpinningBlade {
  VecX qeq;
  double flap = NAN, chord = NAN;   // rad/s; a real (divergent) pair: -rate
  Eigen::VectorXcd flapMode, chordMode;  // position part of the eigenvectors (q_f)
  std::complex<double> flapLambda, chordLambda;
};

SpinningBlade linearise(const std::shared_ptr<const FfrBeamModel3d>& model, double Omega) {
  const FfrBody3d body("probe", model, FrameState3d{});
  const int nf = body.numElastic(), nq = 7 + nf, nv = 6 + nf;
  VecX q = body.initialCoordinates(), v = VecX::Zero(nv);
  v[5] = Omega;
  MatX dQdq(nv, nq), dQdv(nv, nv);
  for (int it = 0; it < 30; ++it) {
    VecX Q = VecX::Zero(nv);
    body.addInternalForces(q, v, Q);
    dQdq.setZero();
    dQdv.setZero();
    body.addInternalForceJacobians(q, v, dQdq, dQdv);
    const VecX dq = MatX(dQdq.block(6, 7, nf, nf)).fullPivLu().solve(Q.tail(nf));
    q.tail(nf) -= dq;
    if (dq.norm() < 1e-15 * (1.0 + q.tail(nf).norm())) break;
  }
  dQdq.setZero();
  dQdv.setZero();
  body.addInternalForceJacobians(q, v, dQdq, dQdv);
  const MatX Minv = MatX(body.invariants().mff).inverse();
  MatX A = MatX::Zero(2 * nf, 2 * nf);
  A.topRightCorner(nf, nf).setIdentity();
  A.bottomLeftCorner(nf, nf) = Minv * dQdq.block(6, 7, nf, nf);
  A.bottomRightCorner(nf, nf) = Minv * dQdv.block(6, 6, nf, nf);
  const Eigen::EigenSolver<MatX> es(A);
  SpinningBlade out;
  out.qeq = q.tail(nf);
  const Mat3X& tip = body.invariants().points.back().shape;
  double bestFlap = INFINITY, bestChord = INFINITY;
  for (int k = 0; k < 2 * nf; ++k) {
    const std::complex<double> lam = es.eigenvalues()[k];
    const Eigen::VectorXcd x = es.eigenvectors().col(k).head(nf);
    const Eigen::Vector3cd u = tip.cast<std::complex<double>>() * x;
    const bool isFlap = std::abs(u.z()) > std::abs(u.y());
    double w = lam.imag();  // damped frequency (the section's Rayleigh damping)
    if (std::abs(lam.imag()) <= 1e-9 * std::abs(lam)) {
      if (lam.real() <= 0) continue;  // the decaying one of a real pair
      w = -lam.real();                // divergence: -rate
    } else if (w <= 0) {
      continue;
    }
    if (std::abs(u.y()) + std::abs(u.z()) < 1e-3 * x.norm()) continue;  // torsion, axial
    double& best = isFlap ? bestFlap : bestChord;
    if (std::abs(w) < std::abs(best)) {
      best = w;
      (isFlap ? out.flapMode : out.chordMode) = x / (isFlap ? u.z() : u.y());  // tip amplitude 1
      (isFlap ? out.flapLambda : out.chordLambda) = lam;
    }
  }
  out.flap = bestFlap;
  out.chord = bestChord;
  return out;
}

/// The blade started at its relative equilibrium at spin Omega plus one linear mode
/// (flapwise or chordwise, tip amplitude 1e-4 m: the nonlinear effects, O(amplitude^2),
/// stay below 1e-6), run over `periods` periods (or 1 s of a divergent mode) at rtol
/// 1e-8, atol 1e-12; the tip's motion along z (flapwise) or y (chordwise).
struct TipRun {
  std::vector<double> t, u;
  long steps = 0;
  double cpu = 0;
  bool ok = false;
};

TipRun runBlade(bool stiffening, double Omega, bool flap, double periods) {
  constexpr double kAmplitude = 1e-4;
  TipRun out;
  const auto model = bladeModel(stiffening);
  const SpinningBlade lin = linearise(model, Omega);
  const Eigen::VectorXcd& x = flap ? lin.flapMode : lin.chordMode;
  const std::complex<double> lam = flap ? lin.flapLambda : lin.chordLambda;
  // q(0) = q_eq + Re(c x), q'(0) = Re(lambda c x): the pure mode, c = amplitude
  const VecX qf0 = lin.qeq + kAmplitude * x.real();
  const VecX qf0dot = kAmplitude * (lam * x).real();
  FrameState3d s;
  s.angularVelocity = Vec3(0, 0, Omega);
  System sys;
  auto blade = std::make_unique<FfrBody3d>("blade", model, s, qf0, qf0dot);
  const FfrBody3d* b = blade.get();
  const BodyIndex bi = sys.addBody(std::move(blade));
  sys.addConstraint(std::make_unique<SpatialJoint>("hub", SpatialJointType::Revolute, kGround, JointFrame{}, bi, JointFrame{}));
  sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, JointFrame{}, bi, JointFrame{},
                                                             makeConstantSpeedLaw(Omega, 0.0)));
  sys.finalize();
  const double w = flap ? lin.flap : lin.chord;
  SolverSettings st;
  st.rtol = 1e-8;
  st.atol = 1e-12;
  st.tEnd = w > 0 ? periods * 2 * M_PI / w : 1.0;
  st.outputStep = w > 0 ? 2 * M_PI / w / 200 : 0.01;
  st.progress = false;
  const int oq = sys.coordinateOffset(bi) + 7, nf = b->numElastic();
  const Mat3X& tip = b->invariants().points.back().shape;
  const SimulationSummary r = simulate(sys, st, [&](const OutputSample& o) {
    const Vec3 u = tip * o.q.segment(oq, nf);
    out.t.push_back(o.t);
    out.u.push_back(flap ? u.z() : u.y());
  });
  out.ok = r.ok;
  out.steps = r.stats.steps;
  out.cpu = r.cpuSeconds;
  return out;
}

/// omega = pi (n - 1) / (t_n - t_1) from the n zero crossings (linear interpolation).
double crossingFrequency(const TipRun& r, int& n) {
  std::vector<double> tc;
  for (size_t k = 1; k < r.u.size(); ++k) {
    const double a = r.u[k - 1], b = r.u[k];
    if ((a < 0) != (b < 0)) tc.push_back(r.t[k - 1] + (r.t[k] - r.t[k - 1]) * a / (a - b));
  }
  n = static_cast<int>(tc.size());
  return n >= 2 ? M_PI * (n - 1) / (tc.back() - tc.front()) : NAN;
}

struct SouthwellRow {
  double Omega, flapLin, flapMeasured, chordLin, chordMeasured, kFlap, kChord;
};

/// k = (omega^2 - omega0^2) / Omega^2 of the measured frequencies at each spin speed,
/// omega0 the model's own (non-rotating) frequencies; worst |measured / linearised - 1|.
std::vector<SouthwellRow> southwell(bool stiffening, const std::vector<double>& speeds, double periods,
                                    double& worstMeasurement) {
  const SpinningBlade still = linearise(bladeModel(stiffening), 0.0);
  std::vector<SouthwellRow> rows;
  worstMeasurement = 0;
  for (double Omega : speeds) {
    const SpinningBlade lin = linearise(bladeModel(stiffening), Omega);
    const TipRun f = runBlade(stiffening, Omega, true, periods), c = runBlade(stiffening, Omega, false, periods);
    EXPECT_TRUE(f.ok && c.ok);
    int nf = 0, nc = 0;
    SouthwellRow r{Omega, lin.flap, crossingFrequency(f, nf), lin.chord, crossingFrequency(c, nc), 0, 0};
    EXPECT_GE(std::min(nf, nc), 2 * periods - 1);
    r.kFlap = (r.flapMeasured * r.flapMeasured - still.flap * still.flap) / (Omega * Omega);
    r.kChord = (r.chordMeasured * r.chordMeasured - still.chord * still.chord) / (Omega * Omega);
    worstMeasurement = std::max(
        {worstMeasurement, std::abs(r.flapMeasured / lin.flap - 1), std::abs(r.chordMeasured / lin.chord - 1)});
    std::printf("[ figures ] spinning blade, stiffening %s, Omega %.2f: flapwise %.6f rad/s measured (%.6f linearised), "
                "k = %+.4f; chordwise %.6f (%.6f), k = %+.4f; %d and %d crossings, %ld + %ld steps, %.2f s CPU\n",
                stiffening ? "on " : "off", Omega, r.flapMeasured, lin.flap, r.kFlap, r.chordMeasured, lin.chord,
                r.kChord, nf, nc, f.steps, c.steps, f.cpu + c.cpu);
    rows.push_back(r);
  }
  return rows;
}

// Tolerances of the spinning blade.
//  - kMeasurement: the zero-crossing frequency of a pure linear mode against the
//    linearisation: integration phase error at rtol 1e-8 over a few periods (~1e-7), the
//    amplitude's nonlinear effect (1e-4 m tip: ~1e-7), crossings interpolated linearly at
//    200 outputs per period (error ~(omega dt)^3 / n ~ 1e-6): 1e-5 relative.
//  - Flapwise with stiffening: the Southwell coefficient of the first flapping mode of a
//    uniform cantilever is 1.193 for small Omega (Rayleigh quotient with the
//    non-rotating mode, an upper bound: the mode adapts to the spin, so k falls slightly
//    with Omega); the 8-element model's own small-Omega value is printed (linearised at
//    Omega = 0.1); kSouthwellLow..kSouthwellHigh.
//  - Flapwise without stiffening (linear FFR): the centrifugal field does not act along
//    z, the frequency does not move: |k| < kNoChange.
//  - Chordwise without stiffening: omega^2 = omega0^2 - Omega^2 (centrifugal softening;
//    the Coriolis coupling with the stiff axial motion adds ~1 %): k = -1 within kSoftening.
//  - Chordwise with stiffening: k = 1.193 - 1 = 0.193 lowered a little by the Coriolis
//    coupling (as in the plane, test_ffr_validation): kChordLow..kChordHigh.
// The section has light Rayleigh damping, beta = 1e-3 s (bladeModel): damping ratios
// beta omega / 2 = 1.8e-3 for the first flapwise mode (its frequency moves by ~zeta^2 / 2
// = 2e-6, and the linearisation includes it: its eigenvalues are the damped ones), 0.08
// for the first axial mode. It removes the free axial and high-frequency vibrations that
// the start excites through the nonlinear and Coriolis couplings (~1e-8 m), which BDF at
// orders 3-5 (not A-stable) otherwise resolves: 3500 steps per run instead of 1e5.
constexpr double kMeasurement = 1e-5, kSouthwellLow = 1.15, kSouthwellHigh = 1.20, kNoChange = 1e-3,
                 kSoftening = 0.03, kChordLow = 0.15, kChordHigh = 0.21;

void checkSouthwell(const std::vector<double>& speeds, double periods) {
  const SpinningBlade still = linearise(bladeModel(true), 0.0), slow = linearise(bladeModel(true), 0.1);
  // the model's own flapwise frequency against the continuum 1.875104^2 sqrt(EI / rho A L^4)
  EXPECT_NEAR(still.flap, 1.875104 * 1.875104, 1e-4 * still.flap);
  std::printf("[ figures ] spinning blade: omega0 flapwise %.6f rad/s (continuum 3.516015), chordwise %.6f (7.032030); "
              "linearised Southwell coefficients at Omega = 0.1: flapwise %.4f (uniform cantilever 1.193), chordwise "
              "%.4f\n",
              still.flap, still.chord, (slow.flap * slow.flap - still.flap * still.flap) / 0.01,
              (slow.chord * slow.chord - still.chord * still.chord) / 0.01);
  double m1 = 0, m0 = 0;
  const auto stiff = southwell(true, speeds, periods, m1);
  const auto linear = southwell(false, speeds, periods, m0);
  EXPECT_LT(m1, kMeasurement);
  EXPECT_LT(m0, kMeasurement);
  for (const auto& r : stiff) {
    EXPECT_GT(r.kFlap, kSouthwellLow) << "Omega " << r.Omega;
    EXPECT_LT(r.kFlap, kSouthwellHigh) << "Omega " << r.Omega;
    EXPECT_GT(r.kChord, kChordLow) << "Omega " << r.Omega;
    EXPECT_LT(r.kChord, kChordHigh) << "Omega " << r.Omega;
  }
  for (const auto& r : linear) {
    EXPECT_LT(std::abs(r.kFlap), kNoChange) << "Omega " << r.Omega;
    EXPECT_NEAR(r.kChord, -1.0, kSoftening) << "Omega " << r.Omega;
  }
  std::printf("[ figures ] measured vs linearised frequency: worst %.1e (stiffening), %.1e (linear)\n", m1, m0);
}

}  // namespace

#ifndef FLEXMBD_SPATIAL_VALIDATION_SLOW

TEST(SpatialGeometricStiffening, FlapwiseFrequencyRisesAsSouthwellOnlyWithStiffening) {
  // Omega = 1, 2, 3 rad/s (up to 0.85 omega0 flapwise), 4 periods of each mode.
  checkSouthwell({1.0, 2.0, 3.0}, 4.0);
}

TEST(SpatialGeometricStiffening, ChordwiseMotionDivergesAboveItsFrequencyOnlyWithoutStiffening) {
  // Omega = 1.25 omega0 chordwise (8.79 rad/s). Linear FFR: omega^2 = omega0^2 - Omega^2
  // < 0, the chordwise mode diverges as exp(s t), s = sqrt(Omega^2 - omega0^2) (5.3 /s,
  // less the Coriolis coupling): measured as ln(u(1 s) / u(0)) against the linearisation's
  // real eigenvalue (kRate: the same integration and nonlinear effects as kMeasurement,
  // 1e-4 relative with the growth to 0.02 m). With stiffening it oscillates (bounded) at
  // the linearised frequency (kMeasurement).
  constexpr double kRate = 1e-4;
  const double w0 = linearise(bladeModel(false), 0.0).chord, Omega = 1.25 * w0;
  const SpinningBlade lin = linearise(bladeModel(false), Omega), stiffLin = linearise(bladeModel(true), Omega);
  ASSERT_LT(lin.chord, 0.0) << "the linearisation must diverge";
  const TipRun r = runBlade(false, Omega, false, 0.0);
  ASSERT_TRUE(r.ok);
  const double rate = std::log(r.u.back() / r.u.front()) / (r.t.back() - r.t.front());
  const TipRun s = runBlade(true, Omega, false, 4.0);
  ASSERT_TRUE(s.ok);
  int n = 0;
  const double w = crossingFrequency(s, n);
  double peak = 0;
  for (double u : s.u) peak = std::max(peak, std::abs(u));
  std::printf("[ figures ] spinning blade at Omega = 1.25 omega0 chordwise (%.3f rad/s): linear FFR diverges at %.6f /s "
              "(linearised %.6f, sqrt(Omega^2 - omega0^2) = %.4f), tip %.2e m after 1 s; with stiffening %.6f rad/s "
              "(linearised %.6f), tip <= %.2e m\n",
              Omega, rate, -lin.chord, std::sqrt(Omega * Omega - w0 * w0), r.u.back(), w, stiffLin.chord, peak);
  EXPECT_NEAR(rate, -lin.chord, kRate * -lin.chord);
  EXPECT_NEAR(w, stiffLin.chord, kMeasurement * stiffLin.chord);
  EXPECT_LT(peak, 1.1e-4);
}

#endif

#ifdef FLEXMBD_SPATIAL_VALIDATION_SLOW

// ----- longer variants (label slow) ----------------------------------------------------

TEST(SpatialFlexibleCrankSlow, NodalRodConservesEnergyAndBalancesTheDriverWork) {
  // The rod with 4 nodal elements (axial and torsion fields included: ~2e5 steps at rtol
  // 1e-9, resolving the high modes that the start excites); bounds as in the default suite.
  const EnergyRun e = freeCrankEnergy(4, 0, 1e-9);
  ASSERT_TRUE(e.summary.ok) << e.summary.message;
  EXPECT_LT(e.drift, 1e-6 * e.T0);
  // outputs every 1e-5 s resolve the nodal rod's bending vibration (Simpson); the axial
  // modes' (1e5 rad/s) share of the power is below the integration error
  const WorkRun w = driverWork(4, 0, 1e-9, 1e-5);
  ASSERT_TRUE(w.summary.ok) << w.summary.message;
  EXPECT_LT(w.worst, 1e-5 * w.scale);
}

TEST(SpatialFlexibleCrankSlow, RigidLimitScalesAsOneOverE) {
  // E x 1e4 with modes (the orientation difference, elastic, falls by another 10) and
  // the nodal rod at E x 1e3 (the chord now stretches: F L / (E A) ~ 5e-12 m).
  const RigidLimit r3 = rigidLimit(1e3, 8, 4, 1e-8), r4 = rigidLimit(1e4, 8, 4, 1e-8);
  ASSERT_TRUE(r3.ok && r4.ok);
  EXPECT_NEAR(r3.rotation / r4.rotation, 10.0, 10.0 * 0.05);
  EXPECT_NEAR(r3.deflection / r4.deflection, 10.0, 10.0 * 0.05);
  // The nodal rod's run (1.2e6 steps: it resolves the axial and torsional vibration the
  // start excites) carries more integration error: measured 1e-9 m (frame) and 8e-9 m
  // (slider) at rtol 1e-8; bound 5e-8 m.
  const RigidLimit n3 = rigidLimit(1e3, 4, 0, 1e-8);
  ASSERT_TRUE(n3.ok);
  EXPECT_LT(n3.frame, 5e-8);
  EXPECT_LT(n3.slider, 5e-8);
  EXPECT_LT(n3.rotation, 1e-5);
}

TEST(SpatialGeometricStiffeningSlow, SouthwellOverMoreSpeedsAndPeriods) {
  checkSouthwell({0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5}, 10.0);
}

#endif
