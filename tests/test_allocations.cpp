// The integrator's hot path allocates nothing: after a first call (which may size the
// scratch), a residual and a Jacobian of DaeSystem make zero heap allocations, for
// rigid, nodal-flexible, modal-flexible and given-invariants models, spatial rigid models,
// and for every planar and spatial joint, driver and force type, in every formulation.
//
// The global allocation functions of the process are replaced (malloc and friends;
// operator new and Eigen's aligned allocation go through malloc) and count while a
// window is open. Set FLEXMBD_ALLOC_TRACE=1 to print a backtrace of each counted
// allocation (to find where one comes from).
#include <execinfo.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "builders/planar_builders.hpp"
#include "core/dae_system.hpp"
#include "forces/spatial_forces.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"
#include "core/time_law.hpp"
#include "core/user_function.hpp"
#include "ffr3d_test_models.hpp"
#include "problems/ffr_test_models.hpp"
#include "scene/scene.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/radau_solver.hpp"
#include "sensitivity/sensitivity_run.hpp"
#include "scene/json_reader.hpp"
#include "results/sensitivity_results.hpp"
#include "simulation/simulation.hpp"

// AddressSanitizer replaces the allocation functions itself: under it (make sanitize)
// the counting is off and the tests are skipped.
#if defined(__SANITIZE_ADDRESS__)
#define FLEXMBD_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FLEXMBD_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef FLEXMBD_COUNT_ALLOCATIONS
#define FLEXMBD_COUNT_ALLOCATIONS 1
#endif

namespace {
bool gCounting = false;
bool gInHook = false;
long gCount = 0;

void counted() {
  if (!gCounting || gInHook) return;
  ++gCount;
  if (std::getenv("FLEXMBD_ALLOC_TRACE")) {
    gInHook = true;
    void* frames[24];
    const int n = backtrace(frames, 24);
    backtrace_symbols_fd(frames, n, STDERR_FILENO);
    write(STDERR_FILENO, "----\n", 5);
    gInHook = false;
  }
}
}  // namespace

#if FLEXMBD_COUNT_ALLOCATIONS
extern "C" void* __libc_malloc(size_t);
extern "C" void* __libc_calloc(size_t, size_t);
extern "C" void* __libc_realloc(void*, size_t);
extern "C" void* __libc_memalign(size_t, size_t);

extern "C" void* malloc(size_t n) {
  counted();
  return __libc_malloc(n);
}
extern "C" void* calloc(size_t k, size_t n) {
  counted();
  return __libc_calloc(k, n);
}
extern "C" void* realloc(void* p, size_t n) {
  counted();
  return __libc_realloc(p, n);
}
extern "C" int posix_memalign(void** p, size_t a, size_t n) {
  counted();
  *p = __libc_memalign(a, n);
  return *p ? 0 : 12;  // ENOMEM
}
extern "C" void* aligned_alloc(size_t a, size_t n) {
  counted();
  return __libc_memalign(a, n);
}
#endif

namespace flexmbd {
namespace {

/// Heap allocations made by fn().
template <class Fn>
long allocationsIn(Fn&& fn) {
  gCount = 0;
  gCounting = true;
  fn();
  gCounting = false;
  return gCount;
}

/// A state that is not special (non-zero velocities, accelerations and multipliers),
/// so that every term of the residual and the Jacobian is evaluated.
void genericState(const DaeSystem& dae, VecX& y, VecX& yp) {
  const System& sys = dae.system();
  const int nv = sys.numVelocities();
  const VecX q = sys.initialCoordinates();
  VecX v(nv), a(nv), lambda(sys.numConstraintEquations());
  for (int k = 0; k < nv; ++k) {
    v[k] = 0.3 + 0.01 * k;
    a[k] = -0.2 + 0.02 * k;
  }
  for (int k = 0; k < lambda.size(); ++k) lambda[k] = 1.0 + 0.1 * k;
  dae.packState(q, v, a, lambda, y, yp);
  if (dae.layout().mu >= 0) {
    for (int k = 0; k < dae.layout().m; ++k) y[dae.layout().mu + k] = 1e-3 * (k + 1);
  }
}

/// Checks zero allocations per residual and per Jacobian (sparse sink, as the
/// integrators use it) in each formulation, after one warm-up call of each.
void expectAllocationFree(const System& sys, const std::string& model) {
  if (!FLEXMBD_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  for (Formulation f : {Formulation::Ggl, Formulation::Index3, Formulation::Index1}) {
    SCOPED_TRACE(model + ", " + toString(f));
    const DaeSystem dae(sys, f);
    VecX y, yp;
    genericState(dae, y, yp);
    VecX F(dae.size());
    std::vector<double> values(dae.pattern().nonZeros(), 0.0);
    const auto scratch = dae.makeScratch();
    JacobianSink J = JacobianSink::sparse(values.data(), dae.pattern());
    dae.residual(0.01, y.data(), yp.data(), F.data(), *scratch);
    dae.jacobian(0.01, y.data(), yp.data(), 1e3, J, *scratch);
    EXPECT_EQ(allocationsIn([&] { dae.residual(0.02, y.data(), yp.data(), F.data(), *scratch); }), 0)
        << "heap allocations in one residual";
    EXPECT_EQ(allocationsIn([&] { dae.jacobian(0.02, y.data(), yp.data(), 1e3, J, *scratch); }), 0)
        << "heap allocations in one Jacobian";
    // the counter itself works (a test that cannot fail is no test)
    EXPECT_GT(allocationsIn([&] { VecX tmp(dae.size()); tmp.setZero(); F[0] += tmp[0]; }), 0);
  }
}

Scene loadExample(const std::string& name) {
  return loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + name);
}

TEST(Allocations, RigidSliderCrank) {
  const Scene s = loadExample("slider_crank_rigid.json");
  expectAllocationFree(s.system, "rigid slider crank");
}

// dF/dp of a sensitivity run (sensitivity/sensitivity_run.hpp): the perturbed systems'
// residuals with their own scratch, no allocation per call.
TEST(Allocations, SensitivityResidualDerivative) {
  if (!FLEXMBD_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  const std::string path = std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json";
  const std::string text = jsonread::readSceneFile(path);
  const Scene base = parseSceneText(text, path);
  const SensitivityScenes sc = buildSensitivityScenes(text, path, base, {"bodies[1].section.density"});
  const DaeSystem dae(base.system, Formulation::Ggl);
  const PerturbedDaes perturbed = perturbedDaes(dae, sc.parameters);
  VecX y, yp, dFdp(dae.size());
  genericState(dae, y, yp);
  ResidualDifferences d(perturbed.stencils, 0.0, y, yp);
  d.residualDerivative(0, 0.01, y.data(), yp.data(), dFdp.data());
  EXPECT_EQ(allocationsIn([&] { d.residualDerivative(0, 0.02, y.data(), yp.data(), dFdp.data()); }), 0)
      << "heap allocations in one dF/dp";
  EXPECT_GT(dFdp.cwiseAbs().maxCoeff(), 0.0);  // M(q) v' depends on the density
}

TEST(Allocations, NodalElasticSliderCrank) {
  const Scene s = testmodels::elasticSliderCrank(8, 1.0, 0, 1.0, 1e-6, 1e-8, 1e-4);
  expectAllocationFree(s.system, "nodal elastic slider crank (damped)");
}

TEST(Allocations, ModalElasticSliderCrank) {
  const Scene s = testmodels::elasticSliderCrank(8, 1.0, 3, 1.0, 1e-6, 1e-8);
  expectAllocationFree(s.system, "modal elastic slider crank");
}

TEST(Allocations, GivenInvariantsBariCrank) {
  const Scene s = loadExample("bari_slider_crank.json");
  expectAllocationFree(s.system, "Bari crank (given invariants)");
}

TEST(Allocations, EveryJointDriverAndForceType) {
  // Not a meaningful mechanism: every component type once, evaluated at a generic state.
  System sys;
  RigidBodyProperties p;
  p.mass = 2.0;
  p.inertia = 0.1;
  p.com = Vec2(0.1, 0.02);
  FrameState2d sa, sb, sc;
  sb.position = Vec2(1.0, 0.2);
  sc.position = Vec2(2.0, -0.1);
  sc.angle = 0.3;
  const BodyIndex a = addRigidBody(sys, "a", p, sa);
  const BodyIndex b = addRigidBody(sys, "b", p, sb);
  const BodyIndex c = addRigidBody(sys, "c", p, sc);
  const ConstraintIndex rev = addRevoluteJoint(sys, "rev", kGround, Vec2::Zero(), a, Vec2::Zero());
  const ConstraintIndex pri = addPrismaticJoint(sys, "pri", a, Vec2(0.5, 0.0), b, Vec2::Zero(), Vec2(1.0, 0.1));
  addFixedJoint(sys, "fix", b, Vec2(0.5, 0.0), c, Vec2(-0.5, 0.0));
  addJointDriver(sys, "angle", rev, makeHarmonicLaw(0.2, 3.0));
  addJointDriver(sys, "slide", pri, makeConstantSpeedLaw(0.1, 0.5));
  addBodyCoordinateDriver(sys, "cx", c, "x", makePolynomialLaw({2.0, 0.1}));
  addSpringDamper(sys, "spring", kGround, Vec2(0.0, 1.0), b, Vec2(0.1, 0.0), 100.0, 2.0, 0.5);
  addRotationalSpringDamper(sys, "torsion", rev, 10.0, 0.5, 0.1);
  addAppliedLoad(sys, "load", c, Vec2(0.2, 0.0), makeConstantLaw(1.0), makeHarmonicLaw(2.0, 1.0),
                 makeConstantLaw(0.3));
  sys.setGravity(Vec2(0.0, -9.81));
  sys.finalize();
  expectAllocationFree(sys, "every component type");
}

TEST(Allocations, UserFunctionsOfCppCallables) {
  // core/user_function.hpp: C++ callables as time laws (driver, load) and spring-damper laws
  // (planar and spatial), derivatives by central differences and given: no allocation
  System sys;
  RigidBodyProperties p{2.0, 0.3, Vec2(0.1, 0.0)};
  FrameState2d sa, sb;
  sb.position = Vec2(1.0, 0.2);
  const BodyIndex a = addRigidBody(sys, "a", p, sa);
  const BodyIndex b = addRigidBody(sys, "b", p, sb);
  const ConstraintIndex rev = addRevoluteJoint(sys, "rev", kGround, Vec2::Zero(), a, Vec2::Zero());
  const auto spring = [](double t, double x, double xdot) { return 100.0 * (x - 0.5) + 2.0 * xdot + 0.1 * t * x * x; };
  addJointDriver(sys, "angle", rev, makeUserTimeLaw([](double t) { return 0.2 * std::sin(3.0 * t); }));
  addSpringDamper(sys, "spring", kGround, Vec2(0.0, 1.0), b, Vec2(0.1, 0.0), 0.0, 0.0, 0.0, makeSpringLaw(spring));
  addSpringDamper(sys, "spring2", a, Vec2(0.3, 0.0), b, Vec2(-0.1, 0.0), 0.0, 0.0, 0.0,
                  makeSpringLaw(spring, [](double, double, double) { return std::array<double, 2>{100.0, 2.0}; }));
  addAppliedLoad(sys, "load", b, Vec2(0.2, 0.0), makeUserTimeLaw([](double t) { return 1.0 + t; }), nullptr,
                 makeUserTimeLaw([](double t) { return 0.3 * t; }, [](double) { return 0.3; }));
  sys.setGravity(Vec2(0.0, -9.81));
  sys.finalize();
  expectAllocationFree(sys, "user functions (planar)");

  System s3;
  RigidBody3dProperties q;
  q.mass = 2.0;
  q.inertia = Vec3(0.1, 0.2, 0.25).asDiagonal();
  FrameState3d f;
  const BodyIndex c = s3.addBody(std::make_unique<RigidBody3d>("c", q, f));
  f.position = Vec3(1.0, 0.2, 0.1);
  const BodyIndex d = s3.addBody(std::make_unique<RigidBody3d>("d", q, f));
  JointFrame f0, f1;
  f1.axes = quaternionRotation(Vec4(0.9, 0.1, 0.3, -0.2));
  s3.addConstraint(std::make_unique<SpatialJoint>("hinge", SpatialJointType::Revolute, kGround, f0, c, f0));
  s3.addForce(std::make_unique<SpatialSpringDamper>("spring", kGround, Vec3(0, 1, 0), d, Vec3::Zero(), 0.0, 0.0, 0.0,
                                                    makeSpringLaw(spring)));
  s3.addForce(std::make_unique<SpatialRotationalSpringDamper>("torsion", c, f0, d, f1, 0.0, 0.0, 0.1,
                                                              makeSpringLaw(spring)));
  s3.addForce(std::make_unique<SpatialAppliedLoad>(
      "load", d, Vec3::Zero(),
      std::array<TimeLawPtr, 6>{makeUserTimeLaw([](double t) { return t; }), nullptr, nullptr, nullptr, nullptr,
                                makeUserTimeLaw([](double t) { return 0.5 * t; })}));
  s3.setGravity(Vec3(0.0, 0.0, -9.81));
  s3.finalize();
  expectAllocationFree(s3, "user functions (spatial)");
}

TEST(Allocations, SpatialSliderCrank) {
  const Scene s = loadExample("spatial_slider_crank.json");
  expectAllocationFree(s.system, "spatial slider crank");
}

TEST(Allocations, EverySpatialJointDriverAndForceType) {
  // Not a meaningful mechanism: every spatial component type once, at a generic state.
  System sys;
  RigidBody3dProperties p;
  p.mass = 2.0;
  p.inertia = Vec3(0.1, 0.2, 0.25).asDiagonal();
  std::vector<BodyIndex> b;
  for (int k = 0; k < 8; ++k) {
    FrameState3d s;
    s.position = Vec3(k, 0.1 * k, -0.05 * k);
    s.orientation = quaternionRotation(Vec4(1.0, 0.1 * k, -0.05, 0.02 * k));
    b.push_back(sys.addBody(std::make_unique<RigidBody3d>("b" + std::to_string(k), p, s)));
  }
  JointFrame f0, f1;
  f1.point = Vec3(0.3, -0.1, 0.2);
  f1.axes = quaternionRotation(Vec4(0.9, 0.1, 0.3, -0.2));
  using T = SpatialJointType;
  const T types[] = {T::Spherical, T::Revolute, T::Prismatic, T::Cylindrical, T::Universal, T::Fixed, T::Planar};
  for (int k = 0; k < 7; ++k) {
    sys.addConstraint(std::make_unique<SpatialJoint>("j" + std::to_string(k), types[k], k == 0 ? kGround : b[k - 1],
                                                     f0, b[k], f1));
  }
  sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("angle", b[0], f0, b[1], f1, makeHarmonicLaw(0.2, 3.0)));
  sys.addConstraint(
      std::make_unique<SpatialJointDisplacementDriver>("slide", b[1], f0, b[2], f1, makeConstantSpeedLaw(0.1, 0.5)));
  addBodyCoordinateDriver(sys, "z", b[7], "z", makeConstantLaw(0.0));
  sys.addForce(std::make_unique<SpatialSpringDamper>("spring", kGround, Vec3(0, 1, 0), b[3], f1.point, 100.0, 2.0, 0.5));
  sys.addForce(std::make_unique<SpatialRotationalSpringDamper>("torsion", b[0], f0, b[1], f1, 10.0, 0.5, 0.1));
  sys.addForce(std::make_unique<SpatialBushing>("bushing", b[5], f1, b[6], f0, std::array<double, 6>{1, 2, 3, 4, 5, 6},
                                                std::array<double, 6>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  sys.addForce(std::make_unique<SpatialAppliedLoad>(
      "load", b[4], f1.point,
      std::array<TimeLawPtr, 6>{makeConstantLaw(1.0), nullptr, makeHarmonicLaw(2.0, 1.0), nullptr, makeConstantLaw(0.3), nullptr}));
  sys.setGravity(Vec3(0.0, 0.0, -9.81));
  sys.finalize();
  expectAllocationFree(sys, "every spatial component type");
}

/// A spatial FFR body (three bent beam elements) on a spherical joint at its clamped
/// node, a rigid body on a revolute joint at its tip, a spring to its middle node and a
/// bushing, with gravity and damping; `stiffening`: the body from a beam model with
/// geometric stiffening (its strain energy Hessian per element), else from invariants.
void expectSpatialFlexibleAllocationFree(bool stiffening) {
  using namespace flexmbd::test3d;
  const std::vector<Vec3> nodes = bentNodes();
  const BeamSection3d section = rectangularSection3d(0.03, 0.018, 2.1e11, 8.1e10, 7850.0, 1e-4);
  const Vec3 hint(1.0, -1.0, 0.3);
  System sys;
  FrameState3d s;
  s.orientation = quaternionRotation(Vec4(0.9, 0.1, -0.2, 0.3));
  std::unique_ptr<FfrBody3d> body;
  if (stiffening) {
    BeamMesh3d mesh;
    mesh.nodes = nodes;
    for (int e = 0; e + 1 < static_cast<int>(nodes.size()); ++e) mesh.elements.push_back({e, e + 1, section, hint});
    FfrBeamOptions3d o;
    o.geometricStiffening = true;
    body = std::make_unique<FfrBody3d>("flex", std::make_shared<const FfrBeamModel3d>(mesh, o, "body 'flex'"), s);
  } else {
    body = std::make_unique<FfrBody3d>("flex", makeBeamChain(nodes, section, hint).inv, s);
  }
  const BodyIndex flex = sys.addBody(std::move(body));
  RigidBody3dProperties p;
  p.mass = 0.5;
  p.inertia = Vec3(0.01, 0.02, 0.025).asDiagonal();
  FrameState3d sr;
  sr.position = s.orientation * nodes[3] + Vec3(0.1, 0.0, 0.0);
  const BodyIndex tip = sys.addBody(std::make_unique<RigidBody3d>("tip", p, sr));
  JointFrame g0, f0, f3, t0;
  g0.point = s.orientation * nodes[0];
  f0.point = nodes[0];
  f3.point = nodes[3];
  t0.point = Vec3(-0.1, 0.0, 0.0);
  sys.addConstraint(std::make_unique<SpatialJoint>("ball", SpatialJointType::Spherical, kGround, g0, flex, f0));
  sys.addConstraint(std::make_unique<SpatialJoint>("hinge", SpatialJointType::Revolute, flex, f3, tip, t0));
  sys.addForce(std::make_unique<SpatialSpringDamper>("spring", kGround, Vec3(0, 1, 0), flex, nodes[2], 100.0, 2.0, 0.5));
  sys.addForce(std::make_unique<SpatialBushing>("bushing", flex, f3, tip, t0, std::array<double, 6>{1, 2, 3, 4, 5, 6},
                                                std::array<double, 6>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  sys.setGravity(Vec3(0.0, 0.0, -9.81));
  sys.finalize();
  expectAllocationFree(sys, stiffening ? "spatial flexible body, stiffening" : "spatial flexible body");
}

TEST(Allocations, SpatialFlexibleBodyWithJointsAndForces) { expectSpatialFlexibleAllocationFree(false); }

TEST(Allocations, SpatialFlexibleBodyWithGeometricStiffening) { expectSpatialFlexibleAllocationFree(true); }

}  // namespace
}  // namespace flexmbd

namespace flexmbd {
namespace {

TEST(Allocations, RadauStepsAtEveryOrderAllocateNothing) {
  // Simeon's crank with the variable-order Radau IIA (its order changes along the run):
  // after a warm-up, steps allocate nothing with dense LU (measured 0 in 167
  // steps); with KLU only a re-pivoting full factorisation may (measured 0 in 160 steps;
  // bounded by the factorisations).
  if (!FLEXMBD_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  const Scene s = loadExample("bari_slider_crank.json");
  const DaeSystem dae(s.system, Formulation::Ggl);
  const ConsistentState init = computeConsistentState(s.system, 0.0, s.system.initialCoordinates(),
                                                      s.system.initialVelocities());
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);
  for (LinearSolverKind ls : {LinearSolverKind::Dense, LinearSolverKind::Klu}) {
    SCOPED_TRACE(toString(ls));
    IntegratorOptions o;
    o.rtol = 1e-8;
    SolverSettings settings = s.solver;  // the scene's classes of absolute tolerances, rtol 1e-8
    settings.rtol = 1e-8;
    o.atol = absoluteTolerances(dae, settings);
    o.linearSolver = ls;
    RadauSolver radau(dae, 0.0, y0, yp0, o, RadauStages{3, 7, 3});
    radau.advance(0.02, 0.1);  // warm-up
    const IntegratorStats before = radau.stats();
    const long allocations = allocationsIn([&] { radau.advance(0.04, 0.1); });
    const IntegratorStats after = radau.stats();
    std::printf("[ measured ] %s: %ld allocations in %ld steps, %ld factorisations\n", toString(ls).c_str(),
                allocations, after.steps - before.steps, after.linearSetups - before.linearSetups);
    EXPECT_GT(after.steps - before.steps, 100);
    if (ls == LinearSolverKind::Dense) EXPECT_EQ(allocations, 0);
    else EXPECT_LE(allocations, 10 * (after.linearSetups - before.linearSetups));
  }
}

}  // namespace
}  // namespace flexmbd
