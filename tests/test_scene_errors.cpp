// Unit tests of the scene reader (scene/scene.hpp): every kind of bad input gives an
// InputError whose one-line message names the offending key, object or value; the
// example scene and a scene using every feature parse into the expected model.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "core/system_evaluation.hpp"
#include "scene/scene.hpp"
#include "linkage/kinematics_scene.hpp"

namespace flexmbd {
namespace {

using nlohmann::json;

/// A valid rigid slider-crank (same model as examples/slider_crank_rigid.json); each
/// test breaks one thing in it.
json baseScene() {
  return json::parse(R"({
    "name": "test slider-crank",
    "bodies": [
      {"name": "crank", "type": "rigid", "mass": 1.0, "inertia": 0.1, "com": [0.5, 0.0]},
      {"name": "rod", "type": "rigid", "mass": 1.0, "inertia": 0.4, "com": [1.0, 0.0],
       "position": [1.0, 0.0]},
      {"name": "slider", "type": "rigid", "mass": 0.5, "inertia": 0.01, "position": [3.0, 0.0]}
    ],
    "joints": [
      {"name": "O1", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], [0, 0]]},
      {"name": "O2", "type": "revolute", "bodies": ["crank", "rod"], "points": [[1, 0], [0, 0]]},
      {"name": "O3", "type": "revolute", "bodies": ["rod", "slider"], "points": [[2, 0], [0, 0]]},
      {"name": "P", "type": "prismatic", "bodies": ["ground", "slider"], "points": [[0, 0], [0, 0]],
       "axis": [1, 0]}
    ],
    "drivers": [
      {"name": "motor", "type": "body_angle", "body": "crank",
       "law": {"type": "constant_speed", "speed": 1.0}}
    ],
    "solver": {"t_end": 1.0}
  })");
}

/// The message of the InputError that parseScene throws (fails the test if none).
std::string errorOf(const json& j) {
  try {
    parseScene(j);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, the scene parsed:\n" << j.dump(2);
  return "";
}

/// Same for JSON text (parseSceneText).
std::string errorOfText(const std::string& text) {
  try {
    parseSceneText(text, "test.json");
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, the scene parsed:\n" << text;
  return "";
}

/// gtest predicate: message contains every given fragment and is one line.
::testing::AssertionResult Mentions(const std::string& message, std::initializer_list<const char*> parts) {
  if (message.find('\n') != std::string::npos) {
    return ::testing::AssertionFailure() << "message is not one line: " << message;
  }
  for (const char* p : parts) {
    if (message.find(p) == std::string::npos) {
      return ::testing::AssertionFailure() << "message lacks '" << p << "': " << message;
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(SceneErrors, BaseSceneIsValid) {
  const Scene s = parseScene(baseScene());
  EXPECT_EQ(s.system.numBodies(), 4);
  EXPECT_TRUE(s.system.isFinalized());
}

TEST(SceneErrors, ASpatialBodyInAPlanarSceneSaysTheDimensionIsMissing) {
  // a newcomer's spatial scene without "dimension": 3: the message names the reason
  for (const char* body : {R"({"name": "b", "type": "rigid", "mass": 1, "inertia": [1, 2, 3]})",
                           R"({"name": "b", "type": "rigid", "mass": 1, "inertia": 1, "position": [0, 0, 1]})",
                           R"({"name": "b", "type": "rigid", "mass": 1, "inertia": 1, "orientation": {"axis": [0, 0, 1], "angle": 1}})"}) {
    json j = baseScene();
    j["bodies"].push_back(json::parse(body));
    EXPECT_TRUE(Mentions(errorOf(j), {"bodies[3] (\"b\")", "looks spatial", "\"dimension\": 3"})) << body;
  }
}

TEST(SceneErrors, ASpatialInertiaOfTwoNumbersSaysWhatItMustBe) {
  json j = {{"dimension", 3},
            {"bodies", {{{"name", "b"}, {"type", "rigid"}, {"mass", 1.0}, {"inertia", {1.0, 2.0}}}}}};
  EXPECT_TRUE(Mentions(errorOf(j), {"key \"inertia\" must be 3 principal moments", "got 2 numbers"}));
  j["bodies"][0]["inertia"] = 5.0;
  EXPECT_TRUE(Mentions(errorOf(j), {"key \"inertia\" must be 3 principal moments", "got a number"}));
}

TEST(SceneErrors, AnOutputPointFarBeyondTheModelIsATypo) {
  // A point output at z = -1e100 ran and exited 0 with coordinates of 1e100;
  // beyond kMaxMagnitudeRatio (1e12) times the model's size it is refused, planar and spatial
  json j = baseScene();
  j["outputs"] = json::array({{{"type", "point"}, {"name", "far"}, {"body", "rod"}, {"point", {1e100, 0.0}}}});
  EXPECT_TRUE(Mentions(errorOf(j), {"outputs[0]", "times the model's size", "expected a point of the body"}));
  j["outputs"][0]["point"] = {1e6, 0.0};  // far, but within the ratio: accepted
  EXPECT_NO_THROW(parseScene(j));
  const json spatial = json::parse(R"({"dimension": 3,
    "bodies": [{"name": "b", "type": "rigid", "mass": 1, "inertia": [1, 1, 1], "position": [1, 0, 0]}],
    "outputs": [{"type": "point", "name": "p", "body": "b", "point": [0, 0, -1e100]}]})");
  EXPECT_TRUE(Mentions(errorOf(spatial), {"outputs[0]", "times the model's size"}));
}

// ----- names ---------------------------------------------------------------------

TEST(SceneErrors, UnknownBodyInJointNamesItAndListsKnownBodies) {
  json j = baseScene();
  j["joints"][2]["bodies"][0] = "rodd";
  EXPECT_TRUE(Mentions(errorOf(j), {"joints[2] (\"O3\"): unknown body \"rodd\" (known bodies: ground, crank, rod, slider)"}));
}

TEST(SceneErrors, DuplicateBodyNames) {
  json j = baseScene();
  j["bodies"][1]["name"] = "crank";
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[1] (\"crank\")", "duplicate"}));
}

TEST(SceneErrors, BodyAndJointWithTheSameName) {
  json j = baseScene();
  j["joints"][0]["name"] = "rod";
  EXPECT_TRUE(Mentions(errorOf(j), {"joints[0] (\"rod\")", "duplicate"}));
}

TEST(SceneErrors, GroundIsAReservedBodyName) {
  json j = baseScene();
  j["bodies"][0]["name"] = "ground";
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[0]", "\"ground\"", "reserved"}));
}

TEST(SceneErrors, UnknownJointInDriver) {
  json j = baseScene();
  j["drivers"][0] = json::parse(
      R"({"name": "m", "type": "joint_angle", "joint": "O9", "law": {"type": "constant", "value": 0}})");
  EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"m\")", "unknown joint \"O9\"", "O1, O2, O3, P"}));
}

// ----- missing and unknown keys ---------------------------------------------------

TEST(SceneErrors, MissingRequiredKeys) {
  {
    json j = baseScene();
    j["bodies"][1].erase("mass");
    EXPECT_TRUE(Mentions(errorOf(j), {"bodies[1] (\"rod\")", "missing required key \"mass\""}));
  }
  {
    json j = baseScene();
    j.erase("bodies");
    EXPECT_TRUE(Mentions(errorOf(j), {"top level", "\"bodies\""}));
  }
  {
    json j = baseScene();
    j["drivers"][0].erase("law");
    EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"motor\")", "\"law\""}));
  }
  {
    json j = baseScene();
    j["drivers"][0]["law"].erase("speed");
    EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"motor\").law", "\"speed\""}));
  }
  {
    json j = baseScene();
    j["joints"][3].erase("axis");  // prismatic joint without its axis
    EXPECT_TRUE(Mentions(errorOf(j), {"joints[3] (\"P\")", "missing required key \"axis\""}));
  }
  {
    json j = baseScene();
    j["joints"][1].erase("points");
    EXPECT_TRUE(Mentions(errorOf(j), {"joints[1] (\"O2\")", "\"points\""}));
  }
}

TEST(SceneErrors, UnknownKeyAtTopLevel) {
  json j = baseScene();
  j["gravty"] = json::array({0.0, -9.81});
  EXPECT_TRUE(Mentions(errorOf(j), {"top level", "unknown key \"gravty\"", "gravity"}));
}

TEST(SceneErrors, UnknownKeyInBody) {
  json j = baseScene();
  j["bodies"][2]["masss"] = 1.0;
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[2] (\"slider\")", "unknown key \"masss\"", "allowed keys", "mass"}));
}

TEST(SceneErrors, UnknownKeyInLaw) {
  json j = baseScene();
  j["drivers"][0]["law"]["sped"] = 2.0;
  EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"motor\").law", "unknown key \"sped\"", "speed, initial"}));
}

TEST(SceneErrors, UnknownKeyInSolver) {
  json j = baseScene();
  j["solver"]["rtoll"] = 1e-6;
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "unknown key \"rtoll\"", "rtol"}));
}

TEST(SceneErrors, AxisOnlyForPrismaticJoints) {
  json j = baseScene();
  j["joints"][0]["axis"] = json::array({1.0, 0.0});
  EXPECT_TRUE(Mentions(errorOf(j), {"joints[0] (\"O1\")", "\"axis\"", "prismatic"}));
}

// ----- values ---------------------------------------------------------------------

TEST(SceneErrors, ZeroAndNegativeMass) {
  json j = baseScene();
  j["bodies"][1]["mass"] = -1;
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[1] (\"rod\"): key \"mass\" must be > 0, got -1"}));
  j["bodies"][1]["mass"] = 0.0;
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[1] (\"rod\"): key \"mass\" must be > 0, got 0"}));
}

TEST(SceneErrors, ZeroInertia) {
  json j = baseScene();
  j["bodies"][0]["inertia"] = 0;
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[0] (\"crank\")", "\"inertia\"", "> 0"}));
}

TEST(SceneErrors, NumberTooLargeForADoubleIsNamed) {
  // nlohmann rejects 1e999 with out_of_range 406 ("number overflow"); the reader turns
  // that into an InputError naming the file and the key.
  json j = baseScene();
  std::string text = j.dump();
  const std::string from = "\"mass\":1.0";
  const auto pos = text.find(from);
  ASSERT_NE(pos, std::string::npos);
  text.replace(pos, from.size(), "\"mass\":1e999");
  EXPECT_TRUE(Mentions(errorOfText(text), {"test.json", "bodies[0].mass", "1e999"}));

  // In an array: the element's index is named.
  text = j.dump();
  const std::string nfrom = "\"name\":\"test slider-crank\"";
  ASSERT_NE(text.find(nfrom), std::string::npos);
  text.replace(text.find(nfrom), nfrom.size(), "\"gravity\":[0,-1e999]," + nfrom);
  EXPECT_TRUE(Mentions(errorOfText(text), {"test.json", "gravity[1]", "1e999"}));
}

TEST(SceneErrors, NonFiniteNumberInJsonObject) {
  // A json built in memory can hold NaN or infinity.
  json j = baseScene();
  j["bodies"][2]["angle"] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[2] (\"slider\")", "\"angle\"", "finite"}));
  j = baseScene();
  j["bodies"][2]["position"][0] = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[2] (\"slider\")", "\"position[0]\"", "finite", "inf"}));
}

TEST(SceneErrors, WrongTypes) {
  {
    json j = baseScene();
    j["bodies"][1]["mass"] = "1.0";
    EXPECT_TRUE(Mentions(errorOf(j), {"bodies[1] (\"rod\")", "\"mass\" must be a number", "string \"1.0\""}));
  }
  {
    json j = baseScene();
    j["bodies"][0]["com"] = json::array({0.5});
    EXPECT_TRUE(Mentions(errorOf(j), {"bodies[0] (\"crank\")", "\"com\"", "2 numbers"}));
  }
  {
    json j = baseScene();
    j["joints"] = json::object();
    EXPECT_TRUE(Mentions(errorOf(j), {"top level", "\"joints\" must be an array"}));
  }
  {
    json j = baseScene();
    j["joints"][0]["bodies"] = "ground";
    EXPECT_TRUE(Mentions(errorOf(j), {"joints[0] (\"O1\")", "\"bodies\""}));
  }
  {
    json j = baseScene();
    j["solver"]["fd_jacobian"] = 1;
    EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"fd_jacobian\"", "true or false"}));
  }
  {
    json j = baseScene();
    j["solver"]["max_steps"] = 10.5;
    EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"max_steps\"", "integer"}));
  }
  {
    json j = baseScene();
    j["solver"]["max_order"] = 7;
    EXPECT_TRUE(Mentions(errorOf(j), {"max_order", "1 to 5", "7"}));
    j["solver"]["max_order"] = 2;
    j["solver"]["initial_step"] = -1e-3;
    EXPECT_TRUE(Mentions(errorOf(j), {"initial_step", "non-negative"}));
    j["solver"]["initial_step"] = 1e-6;
    const Scene s = parseScene(j);  // both keys accepted and carried to the settings
    EXPECT_EQ(s.solver.maxOrder, 2);
    EXPECT_EQ(s.solver.initialStepSize, 1e-6);
  }
  {
    json j = baseScene();
    j["bodies"][0] = json::array();
    EXPECT_TRUE(Mentions(errorOf(j), {"bodies[0]", "expected an object"}));
  }
}

TEST(SceneErrors, BadLawParameters) {
  const auto withLaw = [](const char* law) {
    json j = baseScene();
    j["drivers"][0]["law"] = json::parse(law);
    return errorOf(j);
  };
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "spin_up", "speed": 1, "ramp_time": 0})"),
                       {"drivers[0] (\"motor\").law", "\"ramp_time\"", "> 0"}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "tabulated", "times": [0, 1, 1], "values": [0, 1, 2]})"),
                       {"drivers[0] (\"motor\").law", "times"}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "tabulated", "times": [0, 1], "values": [0, 1, 2]})"),
                       {"drivers[0] (\"motor\").law", "\"times\"", "\"values\"", "same length"}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "polynomial", "coefficients": []})"),
                       {"drivers[0] (\"motor\").law", "\"coefficients\""}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "harmonic", "amplitude": 1, "omega": "fast"})"),
                       {"drivers[0] (\"motor\").law", "\"omega\" must be a number"}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "cubic", "value": 1})"),
                       {"drivers[0] (\"motor\").law", "unknown law type \"cubic\"", "constant_speed"}));
  EXPECT_TRUE(Mentions(withLaw(R"({"type": "constant", "value": 1, "speed": 2})"),
                       {"drivers[0] (\"motor\").law", "unknown key \"speed\""}));
}

TEST(SceneErrors, JointAngleDriverOnPrismaticJoint) {
  json j = baseScene();
  j["drivers"][0] = json::parse(
      R"({"name": "push", "type": "joint_angle", "joint": "P", "law": {"type": "constant", "value": 0}})");
  EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"push\")", "joint \"P\" is prismatic", "joint_displacement"}));
}

TEST(SceneErrors, JointDisplacementDriverOnRevoluteJoint) {
  json j = baseScene();
  j["drivers"][0] = json::parse(
      R"({"name": "push", "type": "joint_displacement", "joint": "O1", "law": {"type": "constant", "value": 0}})");
  EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"push\")", "joint \"O1\" is revolute"}));
}

TEST(SceneErrors, BadFormulationAndLinearSolverNames) {
  json j = baseScene();
  j["solver"]["formulation"] = "index2";
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "formulation", "\"index2\"", "ggl, index3, index1"}));
  j = baseScene();
  j["solver"]["linear_solver"] = "lu";
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"lu\"", "auto, dense, klu"}));
}

TEST(SceneErrors, SolverRanges) {
  json j = baseScene();
  j["solver"]["t_end"] = 0.0;
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"t_end\"", "t_start"}));
  j = baseScene();
  j["solver"]["rtol"] = -1e-6;
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"rtol\" must be > 0"}));
  j = baseScene();
  j["solver"]["output_step"] = 0;
  EXPECT_TRUE(Mentions(errorOf(j), {"solver", "\"output_step\" must be > 0"}));
}

TEST(SceneErrors, UnknownTypes) {
  json j = baseScene();
  j["bodies"][0]["type"] = "elastic";
  EXPECT_TRUE(Mentions(errorOf(j), {"bodies[0] (\"crank\")", "unknown body type \"elastic\"", "rigid", "flexible"}));
  j = baseScene();
  j["joints"][0]["type"] = "hinge";
  EXPECT_TRUE(Mentions(errorOf(j), {"joints[0] (\"O1\")", "unknown joint type \"hinge\"", "revolute"}));
}

TEST(SceneErrors, DriverOnGroundHasNoCoordinate) {
  json j = baseScene();
  j["drivers"][0]["body"] = "ground";
  EXPECT_TRUE(Mentions(errorOf(j), {"drivers[0] (\"motor\")", "ground", "theta"}));
}

TEST(SceneErrors, OutputNamesMustNotClash) {
  json j = baseScene();
  j["outputs"] = json::parse(R"([{"type": "point", "name": "crank", "body": "rod"}])");
  EXPECT_TRUE(Mentions(errorOf(j), {"outputs[0] (\"crank\")", "already used by a body"}));
  j["outputs"] = json::parse(R"([{"type": "energy"}, {"type": "energy"}])");
  EXPECT_TRUE(Mentions(errorOf(j), {"outputs[1]", "energy"}));
}

// ----- JSON text and files ------------------------------------------------------------

TEST(SceneErrors, JsonSyntaxErrorGivesFileAndBytePosition) {
  const std::string m = errorOfText("{\"name\": \"x\",\n \"bodies\": [ }");
  EXPECT_TRUE(Mentions(m, {"test.json", "invalid JSON at byte"}));
}

TEST(SceneErrors, DuplicateJsonKeyIsAnError) {
  // nlohmann would silently keep the last value.
  json j = baseScene();
  std::string text = j.dump();
  const std::string from = "\"mass\":1.0";
  text.replace(text.find(from), from.size(), "\"mass\":1.0,\"mass\":2.0");
  EXPECT_TRUE(Mentions(errorOfText(text), {"test.json", "bodies[0]", "duplicate key \"mass\""}));
}

TEST(SceneErrors, MissingFile) {
  try {
    loadScene("/nonexistent/dir/scene.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(Mentions(e.what(), {"/nonexistent/dir/scene.json"}));
  }
}

// ----- valid scenes ------------------------------------------------------------------

TEST(SceneParse, ExampleSliderCrank) {
  const Scene s = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json");
  EXPECT_EQ(s.name, "rigid slider-crank, l1 = 1, l2 = 2 (source document 000)");
  EXPECT_EQ(s.system.numBodies(), 4);        // ground, crank, rod, slider
  EXPECT_EQ(s.system.numConstraints(), 5);   // O1, O2, O3, P, motor
  EXPECT_EQ(s.system.numCoordinates(), 9);   // 3 rigid bodies x (x, y, theta)
  EXPECT_EQ(s.system.numConstraintEquations(), 2 + 2 + 2 + 2 + 1);
  EXPECT_EQ(s.solver.formulation, Formulation::Ggl);
  EXPECT_DOUBLE_EQ(s.solver.tEnd, 6.283185307179586);
  EXPECT_DOUBLE_EQ(s.solver.outputStep, 0.10471975511965977);
  EXPECT_DOUBLE_EQ(s.solver.rtol, 1e-8);
  EXPECT_FALSE(s.solver.atolVelocity.has_value());
  const auto names = s.system.coordinateNames();
  ASSERT_EQ(names.size(), 9u);
  EXPECT_EQ(names[0], "crank.x");
  EXPECT_EQ(names[8], "slider.theta");
  EXPECT_EQ(s.system.body(s.system.findBody("crank")).mass(), 1.0);
}

TEST(SceneParse, EveryFeature) {
  const json j = json::parse(R"({
    "name": "all features",
    "gravity": [0, -9.81],
    "bodies": [
      {"name": "a", "type": "rigid", "mass": 2, "inertia": 0.5, "position": [1, 0], "angle": 0.3,
       "velocity": [0, 1], "angular_velocity": 1},
      {"name": "b", "type": "rigid", "mass": 1, "inertia": 0.1, "position": [3, 4]},
      {"name": "c", "type": "rigid", "mass": 1, "inertia": 0.1, "position": [0, 5]}
    ],
    "joints": [
      {"name": "J1", "type": "revolute", "bodies": ["ground", "a"], "points": [[0, 0], [-1, 0]]},
      {"name": "J2", "type": "fixed", "bodies": ["a", "c"], "points": [[0, 0], [0, 0]]},
      {"name": "S", "type": "prismatic", "bodies": ["ground", "b"], "points": [[0, 0], [0, 0]],
       "axis": [0.6, 0.8]}
    ],
    "drivers": [
      {"name": "d1", "type": "joint_displacement", "joint": "S",
       "law": {"type": "harmonic", "amplitude": 0.1, "omega": 2, "phase": 0.5, "offset": 5}},
      {"name": "d2", "type": "body_x", "body": "c",
       "law": {"type": "tabulated", "times": [0, 1, 2], "values": [0, 1, 0]}}
    ],
    "forces": [
      {"name": "spring", "type": "spring_damper", "bodies": ["a", "b"], "points": [[1, 0], [0, 0]],
       "stiffness": 100, "damping": 1},
      {"name": "torsion", "type": "rotational_spring_damper", "joint": "J1", "stiffness": 10},
      {"name": "push", "type": "applied_load", "body": "b", "point": [0.1, 0],
       "force_x": {"type": "polynomial", "coefficients": [1, 2, 3]},
       "torque": {"type": "spin_up", "speed": 1, "ramp_time": 0.5}}
    ],
    "outputs": [
      {"type": "point", "name": "tip", "body": "a", "point": [1, 0]},
      {"type": "energy"}
    ],
    "solver": {"formulation": "index3", "rtol": 1e-6, "atol": 1e-8, "atol_velocity": 1e-6,
               "t_start": 0.5, "t_end": 2, "output_step": 0.1, "max_step": 0.01, "max_steps": 1e5,
               "linear_solver": "dense", "fd_jacobian": true}
  })");
  const Scene s = parseScene(j);
  const System& sys = s.system;
  EXPECT_EQ(s.name, "all features");
  EXPECT_EQ(sys.numBodies(), 4);
  EXPECT_EQ(sys.numConstraints(), 5);
  EXPECT_EQ(sys.numForces(), 3);
  EXPECT_EQ(sys.gravity(), Vec3(0, -9.81, 0));
  EXPECT_EQ(s.solver.formulation, Formulation::Index3);
  EXPECT_EQ(s.solver.linearSolver, LinearSolverKind::Dense);
  EXPECT_EQ(s.solver.maxSteps, 100000);
  EXPECT_DOUBLE_EQ(*s.solver.atolVelocity, 1e-6);
  EXPECT_DOUBLE_EQ(s.solver.tStart, 0.5);
  EXPECT_DOUBLE_EQ(s.solver.maxStepSize, 0.01);
  EXPECT_TRUE(s.solver.finiteDifferenceJacobian);

  // Defaults of free_length and free_angle: the springs are relaxed in the initial
  // positions, so with gravity switched off the potential energy there is zero.
  // (Exact up to rounding of a few operations on numbers of order 1.)
  constexpr double kRoundoff = 1e-12;
  const VecX q0 = sys.initialCoordinates();
  const double gravityOnly = [&] {
    double e = 0.0;
    for (int b = 0; b < sys.numBodies(); ++b) {
      const Body& body = sys.body(BodyIndex(b));
      e += body.gravityPotential(q0.segment(sys.coordinateOffset(BodyIndex(b)), body.numCoordinates()),
                                 sys.gravity());
    }
    return e;
  }();
  EXPECT_NEAR(potentialEnergy(sys, q0) - gravityOnly, 0.0, kRoundoff);

  ASSERT_EQ(s.outputs.size(), 2u);
  EXPECT_EQ(s.outputs[0].columnNames(), (std::vector<std::string>{"tip.x", "tip.y", "tip.vx", "tip.vy"}));
  EXPECT_EQ(s.outputs[1].columnNames(),
            (std::vector<std::string>{"energy.kinetic", "energy.potential", "energy.total"}));
  // Tip of body a: r = (1, 0) + A(0.3) (1, 0); v = (0, 1) + omega S A(0.3) (1, 0).
  const auto tip = s.outputs[0].evaluate(sys, q0, sys.initialVelocities());
  ASSERT_EQ(tip.size(), 4u);
  EXPECT_NEAR(tip[0], 1.0 + std::cos(0.3), kRoundoff);
  EXPECT_NEAR(tip[1], std::sin(0.3), kRoundoff);
  EXPECT_NEAR(tip[2], -std::sin(0.3), kRoundoff);
  EXPECT_NEAR(tip[3], 1.0 + std::cos(0.3), kRoundoff);
}

TEST(SceneParse, DefaultsOfAMinimalScene) {
  const Scene s = parseScene(json::parse(R"({"bodies": [{"name": "b", "type": "rigid", "mass": 1, "inertia": 1}]})"));
  EXPECT_EQ(s.name, "");
  EXPECT_EQ(s.system.numCoordinates(), 3);
  EXPECT_EQ(s.system.numConstraints(), 0);
  EXPECT_EQ(s.system.gravity(), Vec3::Zero());
  const SolverSettings d;
  EXPECT_EQ(s.solver.formulation, Formulation::Ggl);
  EXPECT_EQ(s.solver.linearSolver, LinearSolverKind::Automatic);
  EXPECT_EQ(s.solver.rtol, d.rtol);
  EXPECT_EQ(s.solver.atol, d.atol);
  EXPECT_EQ(s.solver.tStart, 0.0);
  EXPECT_EQ(s.solver.tEnd, 1.0);
  EXPECT_EQ(s.solver.outputStep, 0.01);
  EXPECT_EQ(s.solver.maxSteps, 1000000);
  EXPECT_TRUE(s.outputs.empty());
}

TEST(SceneParse, InitialElasticStateOfFlexibleBodies) {
  // A pinned-pinned beam of 2 elements keeps 4 elastic coordinates (node rotations and
  // the middle node's displacements); the given state is the body's initial state.
  json j = json::parse(R"({"bodies": [{"name": "beam", "type": "flexible",
      "section": {"width": 0.01, "height": 0.01, "youngs_modulus": 2e11, "density": 7850},
      "beam": {"length": 1.0, "elements": 2}, "reference": {"type": "pinned_pinned"}}]})");
  const Scene plain = parseScene(j);
  const int nf = plain.system.numCoordinates() - 3;
  ASSERT_GT(nf, 0);
  VecX q(nf), qd(nf);
  for (int k = 0; k < nf; ++k) {
    q[k] = 1e-4 * (k + 1);
    qd[k] = -0.1 * (k + 1);
  }
  j["bodies"][0]["elastic_coordinates"] = std::vector<double>(q.data(), q.data() + nf);
  j["bodies"][0]["elastic_velocities"] = std::vector<double>(qd.data(), qd.data() + nf);
  const Scene s = parseScene(j);
  EXPECT_EQ(s.system.initialCoordinates().tail(nf), q);
  EXPECT_EQ(s.system.initialVelocities().tail(nf), qd);
  j["bodies"][0]["elastic_velocities"] = {1.0};
  const std::string m = errorOf(j);
  EXPECT_NE(m.find("bodies[0] (\"beam\")"), std::string::npos) << m;
  EXPECT_NE(m.find("elastic_velocities"), std::string::npos) << m;
  EXPECT_NE(m.find(std::to_string(nf) + " numbers"), std::string::npos) << m;
  j["bodies"][0]["elastic_velocities"] = "fast";
  EXPECT_NE(errorOf(j).find("elastic_velocities"), std::string::npos);
  // only flexible bodies have an elastic state
  json r = baseScene();
  r["bodies"][0]["elastic_coordinates"] = {0.0};
  EXPECT_NE(errorOf(r).find("unknown key \"elastic_coordinates\""), std::string::npos);
}

TEST(SceneParse, CraigBamptonReductionKeys) {
  // A pinned-pinned beam of 4 elements, Craig-Bampton with interface nodes 0 and 4 and 2
  // fixed-interface modes: 3 constraint modes (psi_0, ux_4, psi_4) + 2 modes.
  json j = json::parse(R"({"bodies": [{"name": "beam", "type": "flexible",
      "section": {"width": 0.01, "height": 0.01, "youngs_modulus": 2e11, "density": 7850},
      "beam": {"length": 1.0, "elements": 4}, "reference": {"type": "pinned_pinned"},
      "reduction": "craig_bampton", "interface_nodes": [0, 4], "modes": 2}]})");
  EXPECT_EQ(parseScene(j).system.numCoordinates(), 3 + 5);
  j["bodies"][0]["modes"] = 0;  // Guyan: static condensation only
  EXPECT_EQ(parseScene(j).system.numCoordinates(), 3 + 3);
  j["bodies"][0].erase("modes");
  EXPECT_EQ(parseScene(j).system.numCoordinates(), 3 + 3);
  j["bodies"][0]["reduction"] = "normal";
  j["bodies"][0].erase("interface_nodes");
  j["bodies"][0]["modes"] = 2;
  EXPECT_EQ(parseScene(j).system.numCoordinates(), 3 + 2);

  // errors name the body and the key
  auto with = [&](const char* key, const json& value, std::initializer_list<const char*> parts) {
    json b = j;
    b["bodies"][0]["reduction"] = "craig_bampton";
    b["bodies"][0]["interface_nodes"] = {0, 4};
    if (value.is_null()) {
      b["bodies"][0].erase(key);
    } else {
      b["bodies"][0][key] = value;
    }
    EXPECT_TRUE(Mentions(errorOf(b), parts)) << key << " = " << value.dump();
  };
  with("reduction", "craig", {"bodies[0] (\"beam\")", "\"reduction\"", "\"craig\"", "craig_bampton"});
  with("reduction", 1, {"bodies[0] (\"beam\")", "\"reduction\"", "must be a string"});
  with("interface_nodes", nullptr, {"bodies[0] (\"beam\")", "missing required key \"interface_nodes\""});
  with("interface_nodes", json::array(), {"bodies[0] (\"beam\")", "\"interface_nodes\"", "non-empty array"});
  with("interface_nodes", 3, {"bodies[0] (\"beam\")", "\"interface_nodes\"", "non-empty array"});
  with("interface_nodes", {0, 5}, {"bodies[0] (\"beam\")", "interface_nodes[1]", "node 5 does not exist", "0..4"});
  with("interface_nodes", {0, -1}, {"bodies[0] (\"beam\")", "interface_nodes[1]", "non-negative integer"});
  with("interface_nodes", {4, 4}, {"bodies[0] (\"beam\")", "interface_nodes[1]", "listed twice"});
  with("interface_nodes", {0, 1.5}, {"bodies[0] (\"beam\")", "interface_nodes[1]", "non-negative integer"});
  with("modes", -1, {"bodies[0] (\"beam\")", "\"modes\"", ">= 0"});
  with("modes", 20, {"bodies[0] (\"beam\")", "fixed-interface mode 20 does not exist"});
  // interface nodes only with craig_bampton; modes 0 only with it
  json n = j;
  n["bodies"][0]["interface_nodes"] = {0};
  EXPECT_TRUE(Mentions(errorOf(n), {"bodies[0] (\"beam\")", "\"interface_nodes\"", "only allowed with"}));
  n["bodies"][0].erase("interface_nodes");
  n["bodies"][0]["modes"] = 0;
  EXPECT_TRUE(Mentions(errorOf(n), {"bodies[0] (\"beam\")", "\"modes\"", ">= 1"}));

  // inertia modes: with a reduction only; 4 more coordinates on this straight beam
  json i = j;
  i["bodies"][0]["inertia_modes"] = true;
  EXPECT_EQ(parseScene(i).system.numCoordinates(), 3 + 2 + 4);
  i["bodies"][0]["reduction"] = "craig_bampton";
  i["bodies"][0]["interface_nodes"] = {0, 4};
  EXPECT_EQ(parseScene(i).system.numCoordinates(), 3 + 5 + 4);
  i["bodies"][0]["inertia_modes"] = "yes";
  EXPECT_TRUE(Mentions(errorOf(i), {"bodies[0] (\"beam\")", "\"inertia_modes\"", "true or false"}));
  json nodal = json::parse(R"({"bodies": [{"name": "beam", "type": "flexible",
      "section": {"width": 0.01, "height": 0.01, "youngs_modulus": 2e11, "density": 7850},
      "beam": {"length": 1.0, "elements": 4}, "reference": {"type": "pinned_pinned"}, "inertia_modes": true}]})");
  EXPECT_TRUE(Mentions(errorOf(nodal), {"bodies[0] (\"beam\")", "\"inertia_modes\"", "needs a modal reduction"}));
}

TEST(SceneParse, ToleranceClassesAndIntegrator) {
  json j = baseScene();
  j["solver"]["atol_angle"] = 1e-9;
  j["solver"]["atol_elastic"] = 1e-12;
  j["solver"]["integrator"] = "ida";
  const Scene s = parseScene(j);
  EXPECT_EQ(s.solver.atolAngle.value_or(0.0), 1e-9);
  EXPECT_EQ(s.solver.atolElastic.value_or(0.0), 1e-12);
  EXPECT_EQ(s.solver.integrator, IntegratorKind::Ida);
  j["solver"]["atol_elastic"] = -1.0;
  EXPECT_NE(errorOf(j).find("atol_elastic"), std::string::npos);
  j["solver"]["atol_elastic"] = 1e-12;
  j["solver"]["integrator"] = "rk4";
  const std::string m = errorOf(j);
  EXPECT_NE(m.find("unknown integrator \"rk4\" (expected one of: auto, ida, radau, radau5, ali3p)"), std::string::npos) << m;
}

}  // namespace
// ----- scene errors -----------------------------------------------------------------------

TEST(NumberText, PlainDecimalsNearOneExponentsFarFromIt) {
  EXPECT_EQ(shortestNumberText(-80), "-80");  // was "-8e+01"
  EXPECT_EQ(shortestNumberText(100), "100");
  EXPECT_EQ(shortestNumberText(123456.5), "123456.5");
  EXPECT_EQ(shortestNumberText(999999), "999999");
  EXPECT_EQ(shortestNumberText(1e6), "1e+06");
  EXPECT_EQ(shortestNumberText(0.1), "0.1");
  EXPECT_EQ(shortestNumberText(1e-4), "0.0001");
  EXPECT_EQ(shortestNumberText(1e-5), "1e-05");
  EXPECT_EQ(shortestNumberText(0.0), "0");
  EXPECT_EQ(shortestNumberText(-2.5e-20), "-2.5e-20");
  for (double x : {-80.0, 0.1, 1.0 / 3.0, 123456.789, 6.02214076e23, 1e-300}) {
    EXPECT_EQ(std::strtod(shortestNumberText(x).c_str(), nullptr), x) << shortestNumberText(x);
  }
}

TEST(SceneKind, ASceneOfAnotherFormatNamesTheCommandItIsFor) {
  const std::string kinematics = R"({"nodes": [], "links": [], "inputs": [], "analysis": {}})";
  try {
    parseSceneText(kinematics, "four_bar.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "four_bar.json is a kinematics scene (key \"analysis\"): run it with \"flexmbd kinematics\"");
  }
  try {
    parseKinematicsSceneText(baseScene().dump(), "crank.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "crank.json is a multibody scene (key \"bodies\"): run it with \"flexmbd run\"");
  }
  // Keys of both formats: not recognised, the reader names the foreign key.
  json mixed = baseScene();
  mixed["links"] = json::array();
  try {
    parseSceneText(mixed.dump(), "mixed.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key \"links\""), std::string::npos) << e.what();
  }
}

}  // namespace flexmbd
