// Contact detection between members (analytic sweep, shared-node rule) and the bad-input
// rules of tensegrity models and scenes, including a reported LCP failure and
// the command line.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "tensegrity/segment_closest_points.hpp"
#include "tensegrity/tensegrity_scene.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

using namespace flexmbd;
using nlohmann::json;

TEST(TensegrityContact, ClosestPointsOfCrossedAndParallelSegments) {
  const auto c = closestPointsOfSegments({0, 0, 0}, {1, 0, 0}, {0.5, -1, 2}, {0.5, 1, 2});
  EXPECT_NEAR(c.distance, 2.0, 1e-15);
  EXPECT_NEAR(c.s, 0.5, 1e-15);
  EXPECT_NEAR(c.t, 0.5, 1e-15);
  const auto p = closestPointsOfSegments({0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0});  // parallel, apart
  EXPECT_NEAR(p.distance, std::sqrt(2.0), 1e-15);
}

// Strut A on the x axis, strut B above it along y at height 1, swept down at speed 1;
// radii 0.05 + 0.05: contact at t = (1 - 0.1)/1 = 0.9, at the point (0.5, 0, 0.05).
// A slack cable joins one end of A to one end of B: it shares a node with each, so no
// pair with it is ever checked, although it touches both at those nodes.
TEST(TensegrityContact, SweptStrutsReportedAtAnalyticTimeSharedNodesNever) {
  TensegrityStructure s(3);
  s.addNode("a0", Eigen::Vector3d(0, 0, 0), 1.0, {true, true, true}, Eigen::Vector3d::Zero());
  s.addNode("a1", Eigen::Vector3d(1, 0, 0), 1.0, {true, true, true}, Eigen::Vector3d::Zero());
  s.addNode("b0", Eigen::Vector3d(0.5, -0.5, 1), 1.0, {}, Eigen::Vector3d(0, 0, -1));
  s.addNode("b1", Eigen::Vector3d(0.5, 0.5, 1), 1.0, {}, Eigen::Vector3d(0, 0, -1));
  s.addStrut("A", 0, 1, 1e3, 1.0, 0.0, BarMassModel::Lumped, 0.05);
  s.addStrut("B", 2, 3, 1e3, 1.0, 0.0, BarMassModel::Lumped, 0.05);
  s.addCable("c", 0, 2, 1e3, 5.0, false, 0.01);
  s.finalize();
  TimeSteppingSettings set;
  set.tEnd = 1.2;
  set.timeStep = 0.01;
  set.detectContacts = true;
  std::vector<TensegrityEvent> contacts;
  const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run(
      {nullptr, [&](const TensegrityEvent& e) {
         if (e.type == TensegrityEvent::Type::Contact) contacts.push_back(e);
       }});
  ASSERT_TRUE(sum.ok) << sum.message;
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].member, "A");
  EXPECT_EQ(contacts[0].other, "B");
  // Nodes move linearly within a step here (no force on B), so the continuous check is
  // exact up to its distance tolerance (1e-10 of the longest member) over speed 1.
  EXPECT_NEAR(contacts[0].t, 0.9, 1e-9);
  EXPECT_NEAR((contacts[0].point - Eigen::Vector3d(0.5, 0.0, 0.05)).norm(), 0.0, 1e-9);
}

namespace {

json twoMassScene() {
  return json::parse(R"({
    "model": "tensegrity", "dimension": 2,
    "nodes": [{"name": "m1", "position": [0, 0], "mass": 1},
              {"name": "m2", "position": [1, 0], "velocity": [2, 0], "mass": 2}],
    "cables": [{"name": "c", "nodes": ["m1", "m2"], "natural_length": 1, "inextensible": true}],
    "solver": {"method": "time_stepping", "t_end": 0.01, "time_step": 0.001}})");
}

std::string errorOf(const json& j) {
  try {
    parseTensegrityScene(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(TensegrityInput, NegativeNaturalLengthOfACable) {
  json j = twoMassScene();
  j["cables"][0]["natural_length"] = -1.0;
  EXPECT_EQ(errorOf(j), "cables[0] (\"c\"): cable \"c\": natural length must be > 0, got -1");
}

TEST(TensegrityInput, NodeWithoutMassOrConstraint) {
  json j = twoMassScene();
  j["nodes"][0]["mass"] = 0.0;
  EXPECT_EQ(errorOf(j),
            "node \"m1\": has no mass (no nodal mass and no strut mass) and is not fixed (expected a mass > 0 or "
            "\"fixed\": true)");
  j["nodes"][0]["fixed"] = true;
  EXPECT_EQ(errorOf(j), "no error");
}

// Rule: a node is the end of at most max_struts_per_node struts (default 1, the document's
// definition of a tensegrity); two members never join the same pair of nodes.
TEST(TensegrityInput, StrutsSharingMoreNodesThanAllowed) {
  json j = twoMassScene();
  j["nodes"].push_back({{"name", "m3"}, {"position", {2, 1}}, {"mass", 1}});
  j["struts"] = json::array({{{"name", "s1"}, {"nodes", {"m1", "m3"}}, {"EA", 100}},
                             {{"name", "s2"}, {"nodes", {"m2", "m3"}}, {"EA", 100}}});
  EXPECT_EQ(errorOf(j),
            "strut \"s2\": node \"m3\" would be the end of 2 struts (a tensegrity has at most 1 per node; raise "
            "max_struts_per_node for a class-k tensegrity)");
  j["max_struts_per_node"] = 2;
  EXPECT_EQ(errorOf(j), "no error");
  j["struts"][1]["nodes"] = {"m3", "m1"};
  EXPECT_EQ(errorOf(j),
            "strut \"s2\": joins the same nodes \"m3\" and \"m1\" as strut \"s1\" (at most one member per pair of nodes)");
}

TEST(TensegrityInput, UnknownKeyAndUnknownNode) {
  json j = twoMassScene();
  j["cables"][0]["lenght"] = 1.0;
  EXPECT_NE(errorOf(j).find("cables[0] (\"c\"): unknown key \"lenght\""), std::string::npos);
  j = twoMassScene();
  j["cables"][0]["nodes"] = {"m1", "m9"};
  EXPECT_EQ(errorOf(j), "cables[0] (\"c\"): unknown node \"m9\"");
}

// Three masses, two inextensible cables snapping at once, solved with Siconos' projected
// Gauss-Seidel limited to one sweep and a 1e-14 tolerance: it does not converge (Siconos
// info 1); what is tested is that the failure is reported with the step and the residual.
TEST(TensegrityInput, LcpFailureReportsResidualAndStep) {
  TensegrityStructure s(2);
  s.addNode("a", Eigen::Vector2d(0, 0), 1.0, {}, Eigen::Vector2d(-1, 0));
  s.addNode("b", Eigen::Vector2d(1, 0), 1.0, {}, Eigen::Vector2d(0, 0));
  s.addNode("c", Eigen::Vector2d(2, 0), 1.0, {}, Eigen::Vector2d(1, 0));
  s.addCable("ab", 0, 1, 0.0, 1.0, true);
  s.addCable("bc", 1, 2, 0.0, 1.0, true);
  s.finalize();
  TimeSteppingSettings set;
  set.tEnd = 0.01;
  set.timeStep = 1e-3;
  set.lcp.method = LcpMethod::ProjectedGaussSeidel;
  set.lcp.maxIterations = 1;
  set.lcp.tolerance = 1e-14;
  const TensegrityRunSummary sum = TensegrityTimeStepper(s, set).run({});
  EXPECT_FALSE(sum.ok);
  EXPECT_NE(sum.message.find("failed at step 1"), std::string::npos) << sum.message;
  EXPECT_NE(sum.message.find("residual"), std::string::npos) << sum.message;
  // The same problem with Lemke: both snaps at once, exact.
  set.lcp.method = LcpMethod::Lemke;
  set.lcp.maxIterations = 100000;
  EXPECT_TRUE(TensegrityTimeStepper(s, set).run({}).ok);
}

TEST(TensegrityCli, RunsTheExampleAndRejectsBadInput) {
  const std::string out = ::testing::TempDir() + "tensegrity_cli";
  const std::string cmd = std::string(FLEXMBD_CLI) + " run " + FLEXMBD_SOURCE_DIR +
                          "/examples/tensegrity_two_masses.json --out " + out + " --quiet > /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream ev(out + "/events.csv");
  std::stringstream ss;
  ss << ev.rdbuf();
  EXPECT_NE(ss.str().find(",snap,c,"), std::string::npos) << ss.str();
  const std::string bad = ::testing::TempDir() + "tensegrity_bad.json";
  {
    json j = twoMassScene();
    j["cables"][0]["natural_length"] = -1.0;
    std::ofstream(bad) << j.dump();
  }
  const std::string cmdBad = std::string(FLEXMBD_CLI) + " run " + bad + " --out " + out + " 2> " + out + "/err.txt";
  const int status = std::system(cmdBad.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  std::ifstream err(out + "/err.txt");
  std::string line;
  std::getline(err, line);
  EXPECT_NE(line.find("natural length must be > 0, got -1"), std::string::npos) << line;
  EXPECT_FALSE(std::ifstream(out + "/results.csv").good());
}
