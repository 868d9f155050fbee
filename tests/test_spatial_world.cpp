// Spatial scenes modelled in the world. Joints placed by a world point
// and axes (key "world", joints/world_frames.hpp), rigid bodies from shapes (key "shape",
// bodies/shape_inertia.hpp), the joint output columns of results.csv
// (joints/joint_outputs.hpp), the example examples/spatial_four_bar.json, and the exit
// status 2 with a message naming the joint and key for bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <fstream>

#include <nlohmann/json.hpp>

#include "bodies/rigid_body_3d.hpp"
#include "bodies/shape_inertia.hpp"
#include "cli_fixture.hpp"
#include "core/rotation_3d.hpp"
#include "core/system_evaluation.hpp"
#include "results/results_writer.hpp"
#include "scene/scene.hpp"
#include "joints/joint_outputs.hpp"
#include "joints/world_frames.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;
using nlohmann::json;

namespace {

const std::string kFourBar = std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_four_bar.json";

json fourBarJson() {
  std::ifstream in(kFourBar);
  return json::parse(in);
}

/// Runs a scene, calling `each` with every output and the joint outputs' values there
/// (columns SpatialJointOutputs::columnNames, angles unwrapped over the run).
struct RunRows {
  std::vector<std::string> names;
  std::vector<double> t;
  std::vector<std::vector<double>> joints;
  std::vector<VecX> q, v;
  double column(std::size_t row, const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    return joints[row][it - names.begin()];
  }
};

RunRows runScene(Scene& scene) {
  RunRows rows;
  SpatialJointOutputs outputs(scene.system);
  rows.names = outputs.columnNames();
  scene.solver.progress = false;
  const SimulationSummary sum = simulate(scene.system, scene.solver, [&](const OutputSample& s) {
    rows.t.push_back(s.t);
    rows.q.push_back(s.q);
    rows.v.push_back(s.v);
    rows.joints.emplace_back();
    outputs.append(s.q, s.v, rows.joints.back());
  });
  EXPECT_TRUE(sum.ok) << sum.message;
  return rows;
}

/// A box of edge lengths (a, b, c) and density rho hinged about world z at its end
/// (world origin), its long edge (body x) at `angle` from world x.
json boxPendulum(double a, double angle, double tEnd, double outputStep) {
  json j = json::parse(R"({"name": "box pendulum", "dimension": 3, "gravity": [0, -9.81, 0],
    "bodies": [{"name": "box", "type": "rigid", "shape": {"type": "box", "size": [1, 0.05, 0.03], "density": 2700}}],
    "joints": [{"name": "hinge", "type": "revolute", "bodies": ["ground", "box"],
                "world": {"point": [0, 0, 0], "axis": [0, 0, 1]}}],
    "solver": {"rtol": 1e-10, "atol": 1e-12}})");
  j["bodies"][0]["shape"]["size"][0] = a;
  j["bodies"][0]["position"] = {0.5 * a * std::cos(angle), 0.5 * a * std::sin(angle), 0.0};
  j["bodies"][0]["orientation"] = {{"axis", {0, 0, 1}}, {"angle", angle}};
  j["solver"]["t_end"] = tEnd;
  j["solver"]["output_step"] = outputStep;
  return j;
}

}  // namespace

// ----- joints placed in the world --------------------------------------------------

TEST(WorldJoints, FramesMadeFromTheWorldSitOnTheBodiesWhereTheWorldFrameIs) {
  // A body turned and moved: the body frame of a world frame maps back onto it,
  // R + A u = p and A C_body = C_world (to rounding, 1e-14).
  System sys;
  FrameState3d s;
  s.position = Vec3(0.3, -0.2, 0.7);
  s.orientation = quaternionRotation(quaternionFromAxisAngle(Vec3(1, 2, -1), 0.8));
  const BodyIndex b = sys.addBody(std::make_unique<RigidBody3d>("b", RigidBody3dProperties{}, s));
  const Vec3 x(1, 0, 0);
  const JointFrame w = worldJointFrame(Vec3(1, 1, 0), Vec3(0, 1, 1), &x, "test");
  EXPECT_NEAR(w.axes.col(2).dot(Vec3(0, 1, 1).normalized()), 1.0, 1e-14);
  EXPECT_NEAR(w.axes.col(0).dot(x), 1.0, 1e-14);  // x hint already normal to the axis: kept
  const auto [fi, fj] = jointFramesFromWorld(sys, kGround, b, w, "test");
  EXPECT_LE((fi.point - w.point).norm(), 1e-14);  // ground: the world frame itself
  EXPECT_LE((fi.axes - w.axes).norm(), 1e-14);
  EXPECT_LE((s.position + s.orientation * fj.point - w.point).norm(), 1e-14);
  EXPECT_LE((s.orientation * fj.axes - w.axes).norm(), 1e-14);
  expectInputError([&] { worldJointFrame(Vec3::Zero(), Vec3::Zero(), nullptr, "joint 'j'"); }, {"joint 'j'", "axis", "non-zero"});
  const Vec3 par(0, 2, 2);
  expectInputError([&] { worldJointFrame(Vec3::Zero(), Vec3(0, 1, 1), &par, "joint 'j'"); }, {"joint 'j'", "x_axis", "parallel"});
}

TEST(WorldJoints, FourBarPlacedInTheWorldMovesAsTheOneWithBodyFrames) {
  // examples/spatial_four_bar.json (world-placed joints) against the same scene with the
  // joint frames written by hand in body axes (each link's joints at +-L/2 on its x axis).
  json world = fourBarJson();
  world["solver"]["rtol"] = 1e-10;  // tighter than the file: the comparison sees the model, not the error control
  world["solver"]["atol"] = 1e-12;
  json local = world;
  const double a = 0.2, b = 0.5, c = 0.4;
  auto frames = [](json pi, json pj) {
    return json::array({{{"point", pi}, {"axis", {0, 0, 1}}}, {{"point", pj}, {"axis", {0, 0, 1}}}});
  };
  const json D = world["joints"][3]["world"]["point"];
  for (auto& jt : local["joints"]) jt.erase("world");
  local["joints"][0]["frames"] = frames({0, 0, 0}, {-a / 2, 0, 0});
  local["joints"][1]["frames"] = frames({a / 2, 0, 0}, {-b / 2, 0, 0});
  local["joints"][2]["frames"] = frames({b / 2, 0, 0}, {c / 2, 0, 0});
  local["joints"][3]["frames"] = frames(D, {-c / 2, 0, 0});
  Scene sw = parseScene(world), sl = parseScene(local);
  // the frames the world placement made are the hand-written points (rounding of the
  // positions in the file: 1e-12)
  const auto& jointC = dynamic_cast<const SpatialJoint&>(sw.system.constraint(sw.system.findConstraint("C")));
  EXPECT_LE((jointC.frameI().point - Vec3(b / 2, 0, 0)).norm(), 1e-12);
  EXPECT_LE((jointC.frameJ().point - Vec3(c / 2, 0, 0)).norm(), 1e-12);
  const RunRows rw = runScene(sw), rl = runScene(sl);
  ASSERT_EQ(rw.q.size(), rl.q.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < rw.q.size(); ++k) worst = std::max(worst, (rw.q[k] - rl.q[k]).lpNorm<Eigen::Infinity>());
  // two integrations of the same motion on different step sequences (the frames' x axes
  // differ, so do the residuals): 3e-6 apart at rtol 1e-8, 1.3e-7 at rtol 1e-10 (the gap
  // follows the tolerance: integration error, not model); bound 1e-6 (m, Euler parameters)
  EXPECT_LE(worst, 1e-6);
  EXPECT_GT((rw.q.back() - rw.q.front()).norm(), 0.1);  // it moved
}

TEST(WorldJoints, FlexibleBodiesTakeWorldPointsAtTheirNodes) {
  json j = json::parse(R"({"dimension": 3, "bodies": [{"name": "beam", "type": "flexible",
      "section": {"width": 0.01, "height": 0.01, "youngs_modulus": 7e10, "poisson_ratio": 0.33, "density": 2700},
      "beam": {"length": 1.0, "elements": 2}, "reference": {"type": "clamped", "node": 0},
      "position": [1, 0, 0], "orientation": {"axis": [0, 0, 1], "angle": 1.5707963267948966}}],
    "joints": [{"name": "pin", "type": "revolute", "bodies": ["ground", "beam"],
                "world": {"point": [1, 0.5, 0], "axis": [0, 0, 1]}}],
    "solver": {"t_end": 0.01}})");
  Scene scene = parseScene(j);  // the middle node of the turned beam is at (1, 0.5, 0)
  const auto& pin = dynamic_cast<const SpatialJoint&>(scene.system.constraint(scene.system.findConstraint("pin")));
  EXPECT_LE((pin.frameJ().point - Vec3(0.5, 0, 0)).norm(), 1e-12);
  j["joints"][0]["world"]["point"] = {1, 0.3, 0};
  expectInputError([&] { parseScene(j); }, {"joints[0] (\"pin\").world", "key \"point\"", "has no node"});
}

// ----- inertia from shapes -----------------------------------------------------------

TEST(Shapes, InertiasAreTheClosedForms) {
  // exact formulas: agreement to rounding (1e-15 relative)
  const double m = 2.5;
  SolidShape box;
  box.size = Vec3(0.3, 0.2, 0.1);
  const Mat3 Ib = shapeInertia(box, m);
  EXPECT_NEAR(Ib(0, 0), m * (0.04 + 0.01) / 12, 1e-15);
  EXPECT_NEAR(Ib(1, 1), m * (0.09 + 0.01) / 12, 1e-15);
  EXPECT_NEAR(Ib(2, 2), m * (0.09 + 0.04) / 12, 1e-15);
  EXPECT_NEAR(shapeVolume(box), 0.006, 1e-17);
  SolidShape cyl;
  cyl.type = SolidShape::Type::Cylinder;
  cyl.radius = 0.05;
  cyl.length = 0.4;
  cyl.axis = 0;
  const Mat3 Ic = shapeInertia(cyl, m);
  EXPECT_NEAR(Ic(0, 0), m * 0.0025 / 2, 1e-15);
  EXPECT_NEAR(Ic(1, 1), m * (3 * 0.0025 + 0.16) / 12, 1e-15);
  EXPECT_NEAR(Ic(2, 2), Ic(1, 1), 1e-15);
  SolidShape tube = cyl;
  tube.type = SolidShape::Type::Tube;
  tube.innerRadius = 0.04;
  tube.axis = 2;
  const Mat3 It = shapeInertia(tube, m);
  EXPECT_NEAR(It(2, 2), m * (0.0016 + 0.0025) / 2, 1e-15);
  EXPECT_NEAR(It(0, 0), m * (3 * (0.0016 + 0.0025) + 0.16) / 12, 1e-15);
  EXPECT_NEAR(shapeVolume(tube), M_PI * (0.0025 - 0.0016) * 0.4, 1e-16);
  SolidShape sphere;
  sphere.type = SolidShape::Type::Sphere;
  sphere.radius = 0.1;
  EXPECT_NEAR(shapeInertia(sphere, m)(1, 1), 0.4 * m * 0.01, 1e-15);
  // a scene body with a density: mass = density x volume
  Scene scene = parseScene(boxPendulum(1.0, 0.0, 0.01, 0.01));
  const auto& body = dynamic_cast<const RigidBody3d&>(scene.system.body(scene.system.findBody("box")));
  EXPECT_NEAR(body.mass(), 2700 * 1.0 * 0.05 * 0.03, 1e-12);
  EXPECT_NEAR(body.inertia()(2, 2), body.mass() * (1.0 + 0.0025) / 12, 1e-12);
}

TEST(Shapes, BoxPendulumSwingsWithThePeriodOfAPhysicalPendulum) {
  // T = 2 pi sqrt(I_O / (m g d)), I_O = m (a^2 + b^2) / 12 + m d^2 about the hinge at the
  // end, d = a / 2; amplitude 0.02 rad: the period is longer by theta0^2 / 16 = 2.5e-5, so
  // the linear period holds to 1e-4 (the bound).
  const double a = 0.8, b = 0.05, g = 9.81, d = a / 2;
  const double T = 2 * M_PI * std::sqrt(((a * a + b * b) / 12 + d * d) / (g * d));
  Scene scene = parseScene(boxPendulum(a, -M_PI / 2 + 0.02, 3.0 * T, 1e-3));
  const RunRows r = runScene(scene);
  // the instants the swing reverses (angle_dot = 0), linearly interpolated
  std::vector<double> reversals;
  for (std::size_t k = 1; k < r.t.size(); ++k) {
    const double w0 = r.column(k - 1, "hinge.angle_dot"), w1 = r.column(k, "hinge.angle_dot");
    if (w0 != 0.0 && (w0 < 0) != (w1 < 0)) reversals.push_back(r.t[k - 1] + (r.t[k] - r.t[k - 1]) * w0 / (w0 - w1));
  }
  ASSERT_GE(reversals.size(), 5u);
  const double measured = (reversals[4] - reversals[0]) / 2.0;  // four half periods
  EXPECT_NEAR(measured / T, 1.0, 1e-4);
}

TEST(Shapes, EightSubBoxesMakeTheWholeBoxByTheParallelAxisTheorem) {
  // A box of edges (a, b, c) cut into eight boxes (a/2, b/2, c/2) at offsets (+-a/4, +-b/4,
  // +-c/4): the parallel-axis sum is exactly the whole box's inertia (to rounding, 1e-15
  // relative). Turning every part and its offset by one rotation A turns the sum: A I A^T.
  const Vec3 e(0.4, 0.3, 0.2);
  const double rho = 7800.0;
  SolidShape whole;
  whole.size = e;
  const RigidBody3dProperties ref = shapeProperties(whole, 0.0, rho);
  const Mat3 A = quaternionRotation(quaternionFromAxisAngle(Vec3(1, -2, 0.5), 0.7));
  std::vector<ShapePart> parts, turned;
  for (int i = 0; i < 8; ++i) {
    SolidShape s;
    s.size = e / 2;
    s.offset = Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1).cwiseProduct(e / 4);
    parts.push_back({s, 0.0, rho});
    s.offset = A * s.offset;
    s.orientation = A;
    turned.push_back({s, 0.0, rho});
  }
  const RigidBody3dProperties sum = shapeProperties(parts);
  const double scale = ref.inertia.norm();
  EXPECT_NEAR(sum.mass, ref.mass, 1e-15 * ref.mass);
  EXPECT_LE((sum.inertia - ref.inertia).norm(), 1e-15 * scale);
  const RigidBody3dProperties rot = shapeProperties(turned);
  EXPECT_LE((rot.inertia - A * ref.inertia * A.transpose()).norm(), 1e-15 * scale);
}

TEST(Shapes, DumbbellIsTheClosedFormAndAnOffCentreSetIsRefused) {
  // Two spheres (m_s, r) at +-d on x and a rod (cylinder m_c, radius rc, length 2d) between:
  // Ixx = 2 (2/5 m_s r^2) + m_c rc^2 / 2, Iyy = Izz = 2 (2/5 m_s r^2 + m_s d^2) + m_c (3 rc^2 + 4 d^2) / 12.
  const double ms = 1.5, r = 0.05, d = 0.3, mc = 0.4, rc = 0.01;
  SolidShape ball;
  ball.type = SolidShape::Type::Sphere;
  ball.radius = r;
  SolidShape rod;
  rod.type = SolidShape::Type::Cylinder;
  rod.radius = rc;
  rod.length = 2 * d;
  rod.orientation = quaternionRotation(quaternionFromAxisAngle(Vec3(0, 1, 0), M_PI / 2));  // its z along body x
  SolidShape left = ball, right = ball;
  left.offset = Vec3(-d, 0, 0);
  right.offset = Vec3(d, 0, 0);
  const RigidBody3dProperties p = shapeProperties({{left, ms, 0.0}, {right, ms, 0.0}, {rod, mc, 0.0}});
  const double ixx = 2 * 0.4 * ms * r * r + mc * rc * rc / 2;
  const double iyy = 2 * (0.4 * ms * r * r + ms * d * d) + mc * (3 * rc * rc + 4 * d * d) / 12;
  EXPECT_NEAR(p.mass, 2 * ms + mc, 1e-15);
  EXPECT_NEAR(p.inertia(0, 0), ixx, 1e-15 * iyy);
  EXPECT_NEAR(p.inertia(1, 1), iyy, 1e-15 * iyy);
  EXPECT_NEAR(p.inertia(2, 2), iyy, 1e-15 * iyy);
  EXPECT_NEAR(p.inertia(0, 1), 0.0, 1e-15 * iyy);
  // without the left ball the centre of mass is at ms d / (ms + mc) on x: refused, and said
  const CompositeInertia c = compositeInertia({{right, ms, 0.0}, {rod, mc, 0.0}});
  EXPECT_NEAR(c.centreOfMass.x(), ms * d / (ms + mc), 1e-15);
  expectInputError([&] { shapeProperties({{right, ms, 0.0}, {rod, mc, 0.0}}); },
                                  {"centre of mass is at [0.2368421", "subtract it from every offset"});
  // in a scene: an array of shapes with offsets and an orientation; errors name the shape
  json j = boxPendulum(1.0, 0.0, 0.01, 0.01);
  j["bodies"][0]["shape"] = json::parse(R"([
      {"type": "sphere", "radius": 0.05, "mass": 1.5, "offset": [-0.3, 0, 0]},
      {"type": "sphere", "radius": 0.05, "mass": 1.5, "offset": [0.3, 0, 0]},
      {"type": "cylinder", "radius": 0.01, "length": 0.6, "mass": 0.4, "orientation": {"axis": [0, 1, 0], "angle": 1.5707963267948966}}])");
  Scene scene = parseScene(j);
  const auto& body = dynamic_cast<const RigidBody3d&>(scene.system.body(scene.system.findBody("box")));
  EXPECT_NEAR(body.inertia()(0, 0), ixx, 1e-12 * iyy);  // the orientation typed to 17 digits
  EXPECT_NEAR(body.inertia()(1, 1), iyy, 1e-12 * iyy);
  j["bodies"][0]["shape"][1]["offset"] = {0.2, 0, 0};
  expectInputError([&] { parseScene(j); }, {"bodies[0] (\"box\").shape", "centre of mass is at"});
  j["bodies"][0]["shape"][1] = 3;
  expectInputError([&] { parseScene(j); }, {"shape[1]", "must be a shape"});
}

TEST(WorldJoints, BushingPlacedInTheWorldStartsUndeflectedAndSpringsAlongItsAxis) {
  // A turned body on a bushing placed by a world frame at its centre with the axis (1, 1, 0):
  // frame I's z axis is that axis, so a push v0 along it oscillates at w = sqrt(kz / m)
  // along it, s(t) = (v0 / w) sin(w t), and nothing moves across it (the frames start
  // aligned, the mount undeflected). rtol 1e-10: 1e-6 of the amplitude, as the other
  // bushing test (tests/test_spatial_dynamics.cpp).
  const double m = 2.0, kz = 800.0, v0 = 0.01;
  const Vec3 e = Vec3(1, 1, 0).normalized(), c(0.3, 0.2, 0.1);
  json j = json::parse(R"({"dimension": 3,
    "bodies": [{"name": "b", "type": "rigid", "mass": 2, "inertia": [0.04, 0.045, 0.05],
                "position": [0.3, 0.2, 0.1], "orientation": {"axis": [1, 2, 3], "angle": 0.7}}],
    "forces": [{"name": "mount", "type": "bushing", "bodies": ["ground", "b"],
                "world": {"point": [0.3, 0.2, 0.1], "axis": [1, 1, 0]},
                "stiffness": [500, 600, 800, 30, 40, 20]}],
    "solver": {"t_end": 1.0, "output_step": 0.005, "rtol": 1e-10, "atol": 1e-12}})");
  j["bodies"][0]["velocity"] = {v0 * e.x(), v0 * e.y(), 0.0};
  Scene scene = parseScene(j);
  const RunRows r = runScene(scene);
  const double w = std::sqrt(kz / m);
  double along = 0.0, across = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const Vec3 d = Vec3(r.q[k].head<3>()) - c;
    along = std::max(along, std::abs(d.dot(e) - v0 / w * std::sin(w * r.t[k])));
    across = std::max(across, (d - d.dot(e) * e).norm());
  }
  EXPECT_LE(along, 1e-6 * v0 / w);
  EXPECT_LE(across, 1e-6 * v0 / w);
  j["forces"][0]["frames"] = json::array({json::object(), json::object()});
  testsupport::expectInputError([&] { parseScene(j); }, {"forces[0] (\"mount\")", "exactly one of \"frames\""});
}

// ----- joint output columns ----------------------------------------------------------

TEST(JointOutputs, DrivenRevoluteReportsTheLawsAngleAndRateOverManyTurns) {
  // a joint_angle driver at 5 rad/s for 3 s (2.4 turns): the angle is unwrapped (15 rad
  // at the end, not wrapped to (-pi, pi]) and equals the law to the driver's accuracy
  // (constraint violation <= 1e-9 rad with rtol 1e-10); the rate is exact on the manifold.
  json j = boxPendulum(0.5, 0.3, 3.0, 0.05);
  j["gravity"] = {0, 0, 0};
  j["drivers"] = json::parse(R"([{"name": "spin", "type": "joint_angle", "joint": "hinge",
                                  "law": {"type": "constant_speed", "speed": 5.0}}])");
  Scene scene = parseScene(j);
  const RunRows r = runScene(scene);
  double worstAngle = 0.0, worstRate = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    worstAngle = std::max(worstAngle, std::abs(r.column(k, "hinge.angle") - 5.0 * r.t[k]));
    worstRate = std::max(worstRate, std::abs(r.column(k, "hinge.angle_dot") - 5.0));
  }
  EXPECT_LE(worstAngle, 1e-8);
  EXPECT_LE(worstRate, 1e-7);
  EXPECT_NEAR(r.column(r.t.size() - 1, "hinge.angle"), 15.0, 1e-8);
}

TEST(JointOutputs, PendulumAngleAndRateHoldItsEnergyAndItsCentreOfMass) {
  // Released horizontal: the angle theta (frame J about frame I's z from the start)
  // gives the centre of mass at (d cos theta, d sin theta) and the energy
  // 1/2 I_O theta'^2 + m g d sin theta = 0 at every output. rtol 1e-10: the state to
  // ~1e-9; bounds 1e-7 m and 1e-7 of m g d.
  const double a = 0.6, b = 0.05, c = 0.03, d = a / 2, g = 9.81;
  Scene scene = parseScene(boxPendulum(a, 0.0, 2.0, 0.01));
  const RunRows r = runScene(scene);
  const double m = 2700 * a * b * c, IO = m * (a * a + b * b) / 12 + m * d * d;
  const int off = scene.system.coordinateOffset(scene.system.findBody("box"));
  double worstPos = 0.0, worstEnergy = 0.0, lowest = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const double th = r.column(k, "hinge.angle"), w = r.column(k, "hinge.angle_dot");
    worstPos = std::max(worstPos, std::hypot(r.q[k][off] - d * std::cos(th), r.q[k][off + 1] - d * std::sin(th)));
    worstEnergy = std::max(worstEnergy, std::abs(0.5 * IO * w * w + m * g * d * std::sin(th)) / (m * g * d));
    lowest = std::min(lowest, th);
  }
  EXPECT_LE(worstPos, 1e-7);
  EXPECT_LE(worstEnergy, 1e-7);
  EXPECT_NEAR(lowest, -M_PI, 1e-3);  // swings down through -pi/2 to the other horizontal
}

TEST(JointOutputs, PrismaticDisplacementIsTheDistanceAlongTheAxis) {
  // A slider on a prismatic joint along (1, 1, 0)/sqrt 2 under gravity -y: the
  // displacement is the centre of mass's motion along the axis, s = -g/(2 sqrt 2) t^2,
  // its rate the velocity along it (rtol 1e-10: bounds 1e-8 m, 1e-8 m/s).
  json j = json::parse(R"({"dimension": 3, "gravity": [0, -9.81, 0],
    "bodies": [{"name": "slider", "type": "rigid", "shape": {"type": "sphere", "radius": 0.05, "mass": 1.0},
                "position": [0.2, 0.2, 0]}],
    "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "slider"],
                "world": {"point": [0.2, 0.2, 0], "axis": [1, 1, 0]}}],
    "solver": {"t_end": 1.0, "output_step": 0.05, "rtol": 1e-10, "atol": 1e-12}})");
  Scene scene = parseScene(j);
  const RunRows r = runScene(scene);
  const Vec3 axis = Vec3(1, 1, 0).normalized();
  double worst = 0.0, worstRate = 0.0, worstLaw = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const double s = r.column(k, "rail.displacement");
    worst = std::max(worst, std::abs(s - (r.q[k].head<3>() - Vec3(0.2, 0.2, 0)).dot(axis)));
    worstRate = std::max(worstRate, std::abs(r.column(k, "rail.displacement_dot") - r.v[k].head<3>().dot(axis)));
    worstLaw = std::max(worstLaw, std::abs(s + 9.81 / (2 * std::sqrt(2.0)) * r.t[k] * r.t[k]));
  }
  EXPECT_LE(worst, 1e-12);  // the same quantity, measured two ways
  EXPECT_LE(worstRate, 1e-12);
  EXPECT_LE(worstLaw, 1e-8);
}

TEST(JointOutputs, UniversalAndSphericalAnglesOfKnownRotations) {
  // frame J turned by angle1 about x_i, then by angle2 about the cross's y axis
  // (C_j = Rx(angle1) Ry(angle2)), and spherical: C_j = R(n, phi) gives phi n; exact up
  // to rounding (1e-14).
  const double a1 = 0.7, a2 = -1.1;
  FrameMotion fi, fj;
  fj.axes = Eigen::AngleAxisd(a1, Vec3::UnitX()).toRotationMatrix() * Eigen::AngleAxisd(a2, Vec3::UnitY()).toRotationMatrix();
  fj.w = Vec3(0.3, 0.0, 0.0) + fj.axes.col(1) * 2.0;  // angle1' = 0.3, angle2' = 2
  double out[6];
  jointOutputValues(SpatialJointType::Universal, fi, fj, out);
  EXPECT_NEAR(out[0], a1, 1e-14);
  EXPECT_NEAR(out[1], a2, 1e-14);
  EXPECT_NEAR(out[2], 0.3, 1e-14);
  EXPECT_NEAR(out[3], 2.0, 1e-14);
  const Vec3 n = Vec3(1, -2, 0.5).normalized();
  fi.axes = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  fj.axes = fi.axes * Eigen::AngleAxisd(2.0, n).toRotationMatrix();
  fj.w = fi.axes * Vec3(1, 2, 3);
  jointOutputValues(SpatialJointType::Spherical, fi, fj, out);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(out[k], 2.0 * n[k], 1e-14);
    EXPECT_NEAR(out[3 + k], k + 1.0, 1e-14);
  }
}

TEST(JointOutputs, ResultsTableHoldsTheJointColumns) {
  Scene scene = loadScene(kFourBar);
  const auto cols = resultColumns(scene);
  for (const char* name : {"A.angle", "A.angle_dot", "D.angle", "D.angle_dot"}) {
    EXPECT_NE(std::find(cols.begin(), cols.end(), name), cols.end()) << name;
  }
}

// ----- the example -------------------------------------------------------------------

TEST(SpatialFourBar, MovesAsThePlanarFourBarAndKeepsItsEnergy) {
  // The same links as a planar scene (dimension 2, the links' moments about z): the
  // crank angle of the 3D scene (joint A's output plus the crank's initial angle) follows
  // the planar crank's. At rtol 1e-10 both: 7e-8 rad apart over 2 s (1e-5 at rtol 1e-8:
  // integration error); bound 1e-6 rad. The 3D energy is conserved to 5e-8 J of 7.2 J;
  // bound 1e-6 J.
  json w = fourBarJson();
  w["solver"]["rtol"] = 1e-10;  // tighter than the file: the comparison sees the model, not the error control
  w["solver"]["atol"] = 1e-12;
  Scene spatial = parseScene(w);
  json planar = {{"name", "planar four-bar"}, {"gravity", {0, -9.81}}, {"joints", json::array()},
                 {"solver", w["solver"]}};
  planar["bodies"] = json::array();
  const char* names[3] = {"crank", "coupler", "rocker"};
  for (int k = 0; k < 3; ++k) {
    const RigidBody3d& body = dynamic_cast<const RigidBody3d&>(spatial.system.body(spatial.system.findBody(names[k])));
    const json& b = w["bodies"][k];
    planar["bodies"].push_back({{"name", names[k]}, {"type", "rigid"}, {"mass", body.mass()},
                                {"inertia", body.inertia()(2, 2)},
                                {"position", {b["position"][0], b["position"][1]}},
                                {"angle", b["orientation"]["angle"]}});
  }
  const double a = 0.2, b = 0.5, c = 0.4;
  auto joint = [](const char* n, const char* bi, const char* bj, json pi, json pj) {
    return json{{"name", n}, {"type", "revolute"}, {"bodies", {bi, bj}}, {"points", {pi, pj}}};
  };
  const json D = w["joints"][3]["world"]["point"];
  planar["joints"] = {joint("A", "ground", "crank", {0, 0}, {-a / 2, 0}),
                      joint("B", "crank", "coupler", {a / 2, 0}, {-b / 2, 0}),
                      joint("C", "coupler", "rocker", {b / 2, 0}, {c / 2, 0}),
                      joint("D", "ground", "rocker", {D[0], D[1]}, {-c / 2, 0})};
  Scene flat = parseScene(planar);
  const RunRows r3 = runScene(spatial);
  std::vector<double> theta;
  flat.solver.progress = false;
  const int th = flat.system.coordinateOffset(flat.system.findBody("crank")) + 2;
  ASSERT_TRUE(simulate(flat.system, flat.solver, [&](const OutputSample& s) { theta.push_back(s.q[th]); }).ok);
  ASSERT_EQ(theta.size(), r3.t.size());
  const double theta0 = w["bodies"][0]["orientation"]["angle"];
  double worst = 0.0;
  for (std::size_t k = 0; k < theta.size(); ++k) worst = std::max(worst, std::abs(theta0 + r3.column(k, "A.angle") - theta[k]));
  EXPECT_LE(worst, 1e-6);
  EXPECT_GT(std::abs(theta.back() - theta0), 0.1);  // it moved
  double e0 = 0.0, worstE = 0.0;
  for (std::size_t k = 0; k < r3.t.size(); ++k) {
    const double E = kineticEnergy(spatial.system, r3.q[k], r3.v[k]) + potentialEnergy(spatial.system, r3.q[k]);
    if (k == 0) e0 = E;
    worstE = std::max(worstE, std::abs(E - e0));
  }
  EXPECT_LE(worstE, 1e-6);
}

// ----- bad input: exit status 2, the joint and key named ----------------------------

TEST_F(Cli, WorldPlacementAndShapeErrorsExitWith2NamingJointAndKey) {
  struct Case {
    const char* what;
    std::function<void(json&)> change;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {"both", [](json& j) { j["joints"][1]["frames"] = json::array({json::object(), json::object()}); },
       {"joints[1] (\"B\")", "exactly one of \"frames\"", "\"world\""}},
      {"neither", [](json& j) { j["joints"][1].erase("world"); }, {"joints[1] (\"B\")", "exactly one of \"frames\""}},
      {"zero axis", [](json& j) { j["joints"][2]["world"]["axis"] = {0, 0, 0}; },
       {"joints[2] (\"C\").world", "key \"axis\"", "non-zero"}},
      {"no axis", [](json& j) { j["joints"][2]["world"].erase("axis"); },
       {"joints[2] (\"C\").world", "revolute joint needs key \"axis\""}},
      {"x_axis parallel", [](json& j) { j["joints"][0]["world"]["x_axis"] = {0, 0, -2}; },
       {"joints[0] (\"A\").world", "x_axis", "parallel"}},
      {"universal without x_axis", [](json& j) { j["joints"][0]["type"] = "universal"; },
       {"joints[0] (\"A\").world", "universal joint needs key \"x_axis\""}},
      {"unknown key", [](json& j) { j["joints"][0]["world"]["axes"] = {0, 0, 1}; },
       {"joints[0] (\"A\").world", "unknown key \"axes\""}},
      {"shape and inertia", [](json& j) { j["bodies"][0]["inertia"] = {1, 1, 1}; },
       {"bodies[0] (\"crank\")", "exactly one of \"inertia\"", "\"shape\""}},
      {"shape and mass", [](json& j) { j["bodies"][0]["mass"] = 1.0; },
       {"bodies[0] (\"crank\")", "\"mass\" does not go with \"shape\""}},
      {"mass and density", [](json& j) { j["bodies"][0]["shape"]["mass"] = 1.0; },
       {"bodies[0] (\"crank\").shape", "exactly one of \"mass\" or \"density\""}},
      {"tube radii", [](json& j) { j["bodies"][0]["shape"] = json::parse(R"({"type": "tube", "inner_radius": 0.02,
          "outer_radius": 0.01, "length": 0.2, "density": 7800})"); },
       {"bodies[0] (\"crank\").shape", "inner_radius", "< outer_radius"}},
  };
  for (const Case& c : cases) {
    json j = fourBarJson();
    c.change(j);
    const fs::path out = dir_ / "out";
    const CliResult r = run("run " + shellQuote(writeScene("bad.json", j).string()) + " --out " + shellQuote(out.string()));
    EXPECT_EQ(r.status, 2) << c.what;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << c.what;
    for (const auto& word : c.words) EXPECT_NE(r.err.find(word), std::string::npos) << c.what << ": " << r.err;
  }
  // a non-finite number (1e999 overflows a double) is refused where it stands
  std::string text = fourBarJson().dump();
  const std::string from = "\"point\":[0.0,0.0,0.0]";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "\"point\":[1e999,0.0,0.0]");
  const fs::path bad = dir_ / "nonfinite.json";
  std::ofstream(bad) << text;
  const CliResult r = run("run " + shellQuote(bad.string()) + " --out " + shellQuote((dir_ / "out2").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("joints[0]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("point"), std::string::npos) << r.err;
}
