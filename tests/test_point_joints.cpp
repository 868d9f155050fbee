// The joints declared through the component registry (point_on_line, planar and
// spatial, with its driver along the line; point_in_plane, spatial): motions against
// their closed forms, reactions against Newton's second law, the key checks that come
// from the declarations, and the generated reference of docs/scene-format.md.
// (Their Jacobians and Hessians: test_jacobians.cpp and test_spatial_jacobians.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "scene/component_reader.hpp"
#include "scene/scene.hpp"
#include "simulation/simulation.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;
using nlohmann::json;

namespace {

constexpr double kG = 9.81;
// The runs below use rtol 1e-10, atol 1e-12 over 1 s: their motions are polynomials of
// degree 2 or harmonics of amplitude 0.2 m, and the integration error measured on them
// is below 1e-9 m; 1e-8 m leaves a margin of ten while a wrong sign of a reaction or a
// missing equation moves them by O(0.1 m).
constexpr double kPositionTol = 1e-8;
// Reactions come from the multipliers, which IDA controls less tightly (algebraic
// variables, outside the error test in GGL form): 1e-6 of m g.
constexpr double kForceTol = 1e-6;

json solver() { return {{"rtol", 1e-10}, {"atol", 1e-12}, {"t_end", 1.0}, {"output_step", 0.1}}; }

/// Runs a scene; calls check(sample, system) at every output.
void runScene(const json& scene, const std::function<void(const OutputSample&, const System&)>& check) {
  Scene s = parseSceneText(scene.dump());
  const SimulationSummary summary = simulate(s.system, s.solver, [&](const OutputSample& o) { check(o, s.system); });
  ASSERT_TRUE(summary.ok) << summary.message;
}

/// The reaction outputs of constraint `name` at a sample (the force on the second body).
VecX reactionsOf(const System& sys, const std::string& name, const OutputSample& o) {
  const ConstraintIndex c = sys.findConstraint(name);
  const Constraint& con = sys.constraint(c);
  return con.reactions(sys.constraintStates(c, o.q.data()), o.lambda.segment(sys.constraintOffset(c), con.numEquations()));
}

json planarBlock() {
  return {{"name", "block"}, {"type", "rigid"}, {"mass", 2.0}, {"inertia", 0.3}, {"com", {0.0, 0.0}},
          {"position", {0.0, 0.0}}, {"angle", 0.4}, {"angular_velocity", 1.5}};
}

}  // namespace

TEST(PointOnLineJoint, PlanarBlockSlidesDownTheLineAtGSinAlphaAndTurnsFreely) {
  // The block's centre of mass on a line through the origin descending at alpha: it
  // accelerates at g sin(alpha) along it; no moment acts about its centre, so its
  // angle turns at its initial rate; the line pushes with m g cos(alpha) along its normal.
  const double alpha = 0.5, m = 2.0;
  const Vec2 d(std::cos(alpha), -std::sin(alpha));
  const json scene = {{"gravity", {0.0, -kG}},
                      {"bodies", {planarBlock()}},
                      {"joints", {{{"name", "line"}, {"type", "point_on_line"}, {"bodies", {"ground", "block"}},
                                   {"points", {{0.0, 0.0}, {0.0, 0.0}}}, {"direction", {d.x(), d.y()}}}}},
                      {"solver", solver()}};
  int samples = 0;
  runScene(scene, [&](const OutputSample& o, const System& sys) {
    const int k = sys.coordinateOffset(sys.findBody("block"));
    const Vec2 r(o.q[k], o.q[k + 1]);
    const double s = 0.5 * kG * std::sin(alpha) * o.t * o.t;
    EXPECT_NEAR(r.dot(d), s, kPositionTol) << "t = " << o.t;
    EXPECT_NEAR(perp(d).dot(r), 0.0, kPositionTol) << "t = " << o.t;
    EXPECT_NEAR(o.q[k + 2], 0.4 + 1.5 * o.t, kPositionTol) << "t = " << o.t;
    const VecX f = reactionsOf(sys, "line", o);  // m a = F + m g
    const Vec2 expected = m * (kG * std::sin(alpha) * d - Vec2(0.0, -kG));
    ASSERT_EQ(f.size(), 2);
    EXPECT_NEAR((Vec2(f[0], f[1]) - expected).norm(), 0.0, kForceTol * m * kG) << "t = " << o.t;
    EXPECT_NEAR(Vec2(f[0], f[1]).norm(), m * kG * std::cos(alpha), kForceTol * m * kG) << "t = " << o.t;
    ++samples;
  });
  EXPECT_EQ(samples, 11);
}

TEST(PointOnLineJoint, PlanarDriverAlongTheLineFollowsItsLawWithTheEffortOfNewton) {
  // Without gravity the driver alone moves the block along the line: s(t) = A sin(w t),
  // effort = m s''(t) (the generalised force the driver applies along s).
  const double m = 2.0, A = 0.2, w = 3.0;
  const Vec2 d = Vec2(1.0, 2.0).normalized();
  const json scene = {
      {"gravity", {0.0, 0.0}},
      {"bodies", {planarBlock()}},
      {"joints", {{{"name", "line"}, {"type", "point_on_line"}, {"bodies", {"ground", "block"}},
                   {"points", {{0.0, 0.0}, {0.0, 0.0}}}, {"direction", {1.0, 2.0}}}}},
      {"drivers", {{{"name", "push"}, {"type", "joint_displacement"}, {"joint", "line"},
                    {"law", {{"type", "harmonic"}, {"amplitude", A}, {"omega", w}}}}}},
      {"solver", solver()}};
  runScene(scene, [&](const OutputSample& o, const System& sys) {
    const int k = sys.coordinateOffset(sys.findBody("block"));
    EXPECT_NEAR(Vec2(o.q[k], o.q[k + 1]).dot(d), A * std::sin(w * o.t), kPositionTol) << "t = " << o.t;
    const VecX effort = reactionsOf(sys, "push", o);
    EXPECT_NEAR(effort[0], -m * A * w * w * std::sin(w * o.t), kForceTol * m * A * w * w) << "t = " << o.t;
  });
}

TEST(PointOnLineJoint, SpatialBodySlidesDownAnInclinedLineAndItsDriverHoldsIt) {
  // A body with its centre on the line through the origin along (1, 1, -1): it falls
  // along it at g / sqrt(3); with a driver holding s = 0.1 + 0.3 t it moves uniformly.
  const Vec3 d = Vec3(1.0, 1.0, -1.0).normalized();
  const json body = {{"name", "bob"}, {"type", "rigid"}, {"mass", 1.5}, {"inertia", {0.2, 0.3, 0.4}},
                     {"position", {0.0, 0.0, 0.0}}};
  json scene = {{"dimension", 3},
                {"gravity", {0.0, 0.0, -kG}},
                {"bodies", {body}},
                {"joints", {{{"name", "line"}, {"type", "point_on_line"}, {"bodies", {"ground", "bob"}},
                             {"points", {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}}, {"direction", {1.0, 1.0, -1.0}}}}},
                {"solver", solver()}};
  runScene(scene, [&](const OutputSample& o, const System& sys) {
    const int k = sys.coordinateOffset(sys.findBody("bob"));
    const Vec3 r = o.q.segment<3>(k);
    EXPECT_NEAR(r.dot(d), 0.5 * kG / std::sqrt(3.0) * o.t * o.t, kPositionTol) << "t = " << o.t;
    EXPECT_NEAR((r - r.dot(d) * d).norm(), 0.0, kPositionTol) << "t = " << o.t;
    const VecX f = reactionsOf(sys, "line", o);  // normal to the line: m (a - g)
    const Vec3 expected = 1.5 * (kG / std::sqrt(3.0) * d - Vec3(0.0, 0.0, -kG));
    EXPECT_NEAR((Vec3(f[0], f[1], f[2]) - expected).norm(), 0.0, kForceTol * 1.5 * kG) << "t = " << o.t;
  });
  scene["bodies"][0]["position"] = {0.1 * d.x(), 0.1 * d.y(), 0.1 * d.z()};
  scene["drivers"] = {{{"name", "hold"}, {"type", "joint_displacement"}, {"joint", "line"},
                       {"law", {{"type", "constant_speed"}, {"speed", 0.3}, {"initial", 0.1}}}}};
  runScene(scene, [&](const OutputSample& o, const System& sys) {
    const Vec3 r = o.q.segment<3>(sys.coordinateOffset(sys.findBody("bob")));
    EXPECT_NEAR(r.dot(d), 0.1 + 0.3 * o.t, kPositionTol) << "t = " << o.t;
    // the driver carries the weight's part along the line: effort = -m g . d
    EXPECT_NEAR(reactionsOf(sys, "hold", o)[0], -1.5 * kG / std::sqrt(3.0), kForceTol * 1.5 * kG) << "t = " << o.t;
  });
}

TEST(PointInPlaneJoint, PointThrownAlongAnInclinedPlaneFollowsTheParabolaOfTheProjectedGravity) {
  // The plane through the origin with normal n = (0, sin b, cos b): the centre moves with
  // the part of gravity in the plane, g - (g . n) n, from its initial velocity in the plane.
  const double b = 0.3;
  const Vec3 n(0.0, std::sin(b), std::cos(b)), g(0.0, 0.0, -kG), v0(2.0, 0.0, 0.0);
  const Vec3 gPlane = g - g.dot(n) * n;
  const json body = {{"name", "puck"}, {"type", "rigid"}, {"mass", 0.5}, {"inertia", {0.01, 0.02, 0.03}},
                     {"position", {0.0, 0.0, 0.0}}, {"velocity", {v0.x(), v0.y(), v0.z()}}};
  const json scene = {{"dimension", 3},
                      {"gravity", {g.x(), g.y(), g.z()}},
                      {"bodies", {body}},
                      {"joints", {{{"name", "plane"}, {"type", "point_in_plane"}, {"bodies", {"ground", "puck"}},
                                   {"points", {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}}, {"normal", {n.x(), n.y(), n.z()}}}}},
                      {"solver", solver()}};
  runScene(scene, [&](const OutputSample& o, const System& sys) {
    const Vec3 r = o.q.segment<3>(sys.coordinateOffset(sys.findBody("puck")));
    EXPECT_NEAR((r - (v0 * o.t + 0.5 * gPlane * o.t * o.t)).norm(), 0.0, kPositionTol) << "t = " << o.t;
    const VecX f = reactionsOf(sys, "plane", o);  // the normal force cancels gravity's normal part
    EXPECT_NEAR((Vec3(f[0], f[1], f[2]) + 0.5 * g.dot(n) * n).norm(), 0.0, kForceTol * 0.5 * kG) << "t = " << o.t;
  });
}

// ----- the key checks come from the declarations ----------------------------------------

namespace {

json lineScene(int dimension, const json& joint) {
  json body = dimension == 2 ? planarBlock()
                             : json{{"name", "block"}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", {1.0, 1.0, 1.0}}};
  json scene = {{"bodies", {body}}, {"joints", {joint}}, {"solver", solver()}};
  if (dimension == 3) scene["dimension"] = 3;
  return scene;
}

json lineJoint(int dimension) {
  if (dimension == 2) {
    return {{"name", "line"}, {"type", "point_on_line"}, {"bodies", {"ground", "block"}},
            {"points", {{0.0, 0.0}, {0.0, 0.0}}}, {"direction", {1.0, 0.0}}};
  }
  return {{"name", "line"}, {"type", "point_on_line"}, {"bodies", {"ground", "block"}},
          {"points", {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}}, {"direction", {1.0, 0.0, 0.0}}};
}

void expectSceneError(const json& scene, const std::vector<std::string>& fragments) {
  expectInputError([&] { parseSceneText(scene.dump()); }, fragments);
}

}  // namespace

TEST(ComponentKeys, MissingUnknownMisshapenAndWrongDimensionAreNamed) {
  for (const int dim : {2, 3}) {
    json j = lineJoint(dim);
    j.erase("direction");
    expectSceneError(lineScene(dim, j), {"joints[0]", "missing key \"direction\" of a point_on_line joint"});
    j = lineJoint(dim);
    j["axis"] = {1.0, 0.0};
    expectSceneError(lineScene(dim, j), {"joints[0]", "unknown key \"axis\"", "name, type, bodies, points, direction"});
    j = lineJoint(dim);
    j["direction"] = dim == 2 ? json{0.0, 0.0} : json{0.0, 0.0, 0.0};
    expectSceneError(lineScene(dim, j), {"joints[0]", "key \"direction\""});
    j = lineJoint(dim);
    j["points"] = {{0.0, 0.0}};
    expectSceneError(lineScene(dim, j), {"joints[0]", "key \"points\""});
    j = lineJoint(dim);
    j["bodies"] = {"ground", "nobody"};
    expectSceneError(lineScene(dim, j), {"joints[0]", "nobody"});
    j = lineJoint(dim);
    j["type"] = "point_on_a_line";
    expectSceneError(lineScene(dim, j), {"unknown joint type \"point_on_a_line\"", "point_on_line"});
  }
  json plane = lineJoint(2);
  plane["type"] = "point_in_plane";
  expectSceneError(lineScene(2, plane), {"joints[0]", "a point_in_plane joint is spatial", "\"dimension\": 3"});
  json angle = lineScene(2, lineJoint(2));
  angle["drivers"] = {{{"name", "turn"}, {"type", "joint_angle"}, {"joint", "line"},
                       {"law", {{"type", "constant"}, {"value", 0.0}}}}};
  expectSceneError(angle, {"drivers[0]", "needs a joint with an angle to drive", "\"line\" (point_on_line) has none"});
}

TEST(ComponentReference, DocsHoldTheGeneratedReference) {
  // docs/scene-format.md holds, between its two markers, the reference that
  // componentReference() writes from the declarations; FLEXMBD_UPDATE_REFERENCE=1
  // rewrites that part of the page.
  const std::string path = FLEXMBD_SCENE_FORMAT_DOC;
  std::ifstream in(path);
  ASSERT_TRUE(in) << "cannot read " << path;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::string begin = scenereaders::kReferenceBegin, end = scenereaders::kReferenceEnd;
  const std::size_t a = text.find(begin), b = text.find(end);
  ASSERT_NE(a, std::string::npos) << path << " has no marker " << begin;
  ASSERT_NE(b, std::string::npos) << path << " has no marker " << end;
  const std::string generated = "\n" + scenereaders::componentReference();
  const std::string current = text.substr(a + begin.size(), b - a - begin.size());
  if (current != generated && std::getenv("FLEXMBD_UPDATE_REFERENCE")) {
    std::ofstream(path) << text.substr(0, a + begin.size()) << generated << text.substr(b);
    GTEST_SKIP() << "rewrote the generated reference of " << path;
  }
  EXPECT_EQ(current, generated) << path << " is stale: run this test with FLEXMBD_UPDATE_REFERENCE=1";
}
