// Spatial scene files ("dimension": 3): the example spatial slider crank read from its
// file and run against the closed form, and the strict reader's messages for bad input.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include <nlohmann/json.hpp>

#include "scene/scene.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;

namespace {

std::string example() { return std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank.json"; }

/// The example with one change applied to its JSON.
void expectSceneError(const std::function<void(nlohmann::json&)>& change, const std::vector<std::string>& fragments) {
  std::ifstream in(example());
  nlohmann::json j = nlohmann::json::parse(in);
  change(j);
  expectInputError([&] { parseScene(j); }, fragments);
}

}  // namespace

TEST(SpatialScene, ExampleSliderCrankRunsFromItsFileToTheClosedForm) {
  Scene scene = loadScene(example());
  const System& sys = scene.system;
  ASSERT_EQ(sys.numCoordinates(), 21);
  ASSERT_EQ(sys.numVelocities(), 18);
  // the closed form of tests/test_spatial_dynamics.cpp (r 0.15, L 0.45, h 0.1, w 2 pi, th0 0.3)
  const double r = 0.15, L = 0.45, h = 0.1, w = 2 * M_PI, th0 = 0.3;
  const auto s = [&](double th) { return r * std::cos(th) + std::sqrt(L * L - h * h - r * r * std::sin(th) * std::sin(th)); };
  const int xs = sys.coordinateOffset(sys.findBody("slider"));
  double worst = 0.0;
  scene.solver.progress = false;
  const SimulationSummary sum = simulate(sys, scene.solver, [&](const OutputSample& o) {
    worst = std::max(worst, std::abs(o.q[xs] - s(th0 + w * o.t)));
  });
  ASSERT_TRUE(sum.ok) << sum.message;
  // rtol 1e-8 in the file: the slider position to ~1e-9 m; bound 1e-7 m
  EXPECT_LE(worst, 1e-7);
  // columns: positions, quaternions, body-axes angular velocities, 6 reaction components
  const auto names = sys.velocityNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "rod.wz"), names.end());
  ASSERT_EQ(scene.outputs.size(), 2u);
  EXPECT_EQ(scene.outputs[1].columnNames().size(), 6u);
}

TEST(SpatialScene, BadInputNamesTheKeyAndWhatWasExpected) {
  expectSceneError([](auto& j) { j["dimension"] = 4; }, {"dimension", "<= 3"});
  expectSceneError([](auto& j) { j["bodies"][0]["orientation"] = {{"axis", {0, 0, 1}}}; },
                   {"bodies[0] (\"crank\").orientation", "both \"axis\" and \"angle\""});
  expectSceneError([](auto& j) { j["bodies"][1]["orientation"] = {{"matrix", {{1, 0, 0}, {0, 1, 0}, {0, 0, 2}}}}; },
                   {"bodies[1] (\"rod\").orientation", "not a rotation"});
  expectSceneError([](auto& j) { j["bodies"][0]["inertia"] = {1.0, 1.0, 3.0}; }, {"crank", "I1 + I2 >= I3"});
  expectSceneError([](auto& j) { j["bodies"][0]["type"] = "flexible"; }, {"bodies[0]", "unknown key \"inertia\"", "flexible body in a spatial scene"});
  expectSceneError([](auto& j) { j["joints"][0]["type"] = "hinge"; }, {"joints[0]", "hinge"});
  expectSceneError([](auto& j) { j["joints"][0]["frames"] = nlohmann::json::array({nlohmann::json::object()}); },
                   {"joints[0] (\"bearing\")", "two frames"});
  expectSceneError([](auto& j) { j["joints"][0]["frames"][0]["axis"] = {0, 0, 0}; }, {"frames[0]", "non-zero"});
  expectSceneError([](auto& j) { j["drivers"][0]["joint"] = "pin"; }, {"drivers[0]", "revolute or cylindrical", "spherical"});
  expectSceneError([](auto& j) { j["drivers"][0]["type"] = "body_angle"; }, {"drivers[0]", "joint_angle"});
  expectSceneError([](auto& j) { j["gravity"] = {0, -9.81}; }, {"gravity", "3 numbers"});
  expectSceneError([](auto& j) { j["outputs"][1]["type"] = "deflection"; }, {"outputs[1]", "crank", "not a flexible body made from a beam mesh"});
}
