// The spatial builders (builders/spatial_builders.hpp): a model built with them is the
// model the scene reader makes of the same scene (the heavy top and the world-placed
// four-bar, bit for bit), drivers and springs take the joint's frames, and bad input is
// an InputError naming the element.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bodies/shape_inertia.hpp"
#include "builders/planar_builders.hpp"
#include "builders/spatial_builders.hpp"
#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using flexmbd::testsupport::kPi;

namespace {

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

/// The final state of a run (q, v at t_end).
struct Final {
  VecX q, v;
  bool ok = false;
};
Final run(const System& sys, const SolverSettings& s) {
  Final f;
  const SimulationSummary sum = simulate(sys, s, [&](const OutputSample& o) {
    f.q = o.q;
    f.v = o.v;
  });
  f.ok = sum.ok;
  return f;
}

// examples/heavy_top.json, built in C++.
System heavyTop() {
  System sys;
  SolidShape disc;
  disc.type = SolidShape::Type::Cylinder;
  disc.radius = 0.05;
  disc.length = 0.02;
  FrameState3d init;
  init.position = Vec3(0, -0.049999999999999996, 0.08660254037844388);
  init.orientation = rotationFromAxisAngle(Vec3::UnitX(), 0.5235987755982988);
  init.velocity = Vec3(0.14052074486221316, 0, 0);
  init.angularVelocity = Vec3(0, 1.4052074486221315, 300.0);
  const BodyIndex top = addRigidBody3d(sys, "top", shapeProperties(disc, 1.0, 0.0), init);
  addSpatialJointAtWorld(sys, "tip", SpatialJointType::Spherical, kGround, top, Vec3::Zero());
  sys.setGravity(Vec3(0, 0, -9.81));
  sys.finalize();
  return sys;
}

}  // namespace

// The builders make what the reader makes: same coordinates, same run, to the last bit.
TEST(SpatialBuilders, HeavyTopEqualsItsSceneFile) {
  Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/heavy_top.json");
  const System built = heavyTop();
  ASSERT_EQ(built.initialCoordinates(), scene.system.initialCoordinates());
  ASSERT_EQ(built.initialVelocities(), scene.system.initialVelocities());
  SolverSettings s = scene.solver;
  s.tEnd = 0.2;  // ten turns of the 300 rad/s spin: enough to compare, short for a unit test
  const Final a = run(built, s), b = run(scene.system, s);
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.v, b.v);
}

// A world-placed revolute driven at constant speed: the driver uses the joint's frames,
// so the body turns about the world axis given; the spring's free angle and the spring's
// free length default to their initial values (no load at the start).
TEST(SpatialBuilders, DriverAndSpringsUseTheJointFrames) {
  System sys;
  RigidBody3dProperties p;
  p.mass = 2.0;
  p.inertia = Vec3(0.01, 0.02, 0.03).asDiagonal();
  FrameState3d init;
  init.position = Vec3(0.5, 0, 1);
  init.orientation = rotationFromQuaternion(Vec4(1, 0, 0, 1));  // 90 deg about z
  const BodyIndex arm = addRigidBody3d(sys, "arm", p, init);
  const Vec3 axis = Vec3::UnitY();
  const ConstraintIndex hinge =
      addSpatialJointAtWorld(sys, "hinge", SpatialJointType::Revolute, kGround, arm, Vec3(0, 0, 1), &axis);
  EXPECT_NEAR(initialJointAngle(sys, hinge), 0.0, 1e-15);  // the frames coincide initially
  const ForceIndex rs = addSpatialRotationalSpringDamper(sys, "rs", hinge, 10.0, 0.0);
  const ForceIndex sd = addSpatialSpringDamper(sys, "sd", kGround, Vec3(0, 0, 0), arm, Vec3(0, 0, 0), 5.0, 0.0);
  addJointDriver(sys, "motor", hinge, makeConstantSpeedLaw(2.0));  // the planar name dispatches to the spatial driver
  sys.finalize();
  EXPECT_EQ(sys.force(rs).typeName(), "rotational_spring_damper");
  EXPECT_EQ(sys.force(sd).typeName(), "spring_damper");
  SolverSettings s;
  s.tEnd = 0.5;
  s.outputStep = 0.5;
  const Final f = run(sys, s);
  ASSERT_TRUE(f.ok);
  // the centre of mass turns about the world y axis through (0, 0, 1), radius 0.5, by
  // theta = 2 t = 1 rad: rotation about +y takes x into -z
  const double theta = 1.0;
  EXPECT_NEAR(f.q[0], 0.5 * std::cos(theta), 1e-6);  // integration tolerance (default rtol 1e-6)
  EXPECT_NEAR(f.q[1], 0.0, 1e-9);
  EXPECT_NEAR(f.q[2], 1.0 - 0.5 * std::sin(theta), 1e-6);
}

TEST(SpatialBuilders, BadInputNamesTheElement) {
  System sys;
  RigidBody3dProperties p;
  const BodyIndex b = addRigidBody3d(sys, "b", p, FrameState3d{});
  const ConstraintIndex prism =
      addSpatialJoint(sys, "slide", SpatialJointType::Prismatic, kGround, JointFrame{}, b, JointFrame{});
  EXPECT_NE(errorOf([&] { addSpatialJointAtWorld(sys, "h", SpatialJointType::Revolute, kGround, b, Vec3::Zero()); })
                .find("joint 'h': a revolute joint needs its axis"),
            std::string::npos);
  const Vec3 z = Vec3::UnitZ();
  EXPECT_NE(errorOf([&] { addSpatialJointAtWorld(sys, "u", SpatialJointType::Universal, kGround, b, Vec3::Zero(), &z); })
                .find("joint 'u': a universal joint needs x_axis"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { addJointAngleDriver(sys, "d", prism, makeConstantLaw(0.0)); })
                .find("driver 'd': a joint angle driver needs a revolute or cylindrical joint, but joint 'slide' is prismatic"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { spatialJointTypeFromString("hinge"); }).find("unknown spatial joint type 'hinge' (expected one of: spherical, revolute"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { addSpatialJoint(sys, "x", SpatialJointType::Fixed, kGround, JointFrame{}, BodyIndex(7), JointFrame{}); })
                .find("joint 'x': body index 7 does not exist"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { rotationFromAxisAngle(Vec3::Zero(), 1.0); }).find("axis must be a finite non-zero vector"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { rotationFromQuaternion(Vec4::Zero()); }).find("not all zero"), std::string::npos);
  // a planar body in a spatial joint
  const BodyIndex flat = addRigidBody(sys, "flat", RigidBodyProperties{1.0, 1.0, Vec2::Zero()}, FrameState2d{});
  EXPECT_NE(errorOf([&] { addSpatialJoint(sys, "mix", SpatialJointType::Spherical, b, JointFrame{}, flat, JointFrame{}); })
                .find("joint 'mix'"),
            std::string::npos);
  std::array<double, 6> k{}, c{};
  k[2] = -1.0;
  EXPECT_NE(errorOf([&] { addSpatialBushing(sys, "bush", kGround, JointFrame{}, b, JointFrame{}, k, c); })
                .find("force 'bush': stiffness[2] must be finite and >= 0"),
            std::string::npos);
}
