// The scene body of an FE export ("type": "fe_body", docs/scene-format.md "FE bodies";
// scene/fe_body_reader.hpp): the rotor of ../shared/data/exudyn-rotor read from a scene with
// paths relative to the scene file, against the FeBodyModel built directly; a point mass
// against the closed-form change of mass, first and second moment; modal damping against
// the decay of a free vibration, exp(-zeta omega t); the key errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bodies/fe_body_model.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "scene/scene.hpp"
#include "fe_test_support.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;
using json = nlohmann::json;
namespace fs = std::filesystem;
using flexmbd::fetest::expectMentions;

namespace {

const std::string kRotorDir = std::string(FLEXMBD_SOURCE_DIR) + "/../shared/data/exudyn-rotor";
// the scene's own name: the files it names are relative to its folder (the file itself need not exist)
const std::string kSceneInDataDir = kRotorDir + "/rotor.json";

#define SKIP_WITHOUT_ROTOR_DATA() \
  if (!fs::exists(kRotorDir + "/rotorDiscTest.inp")) GTEST_SKIP() << "no rotor data at " << kRotorDir

json abaqusFiles() {
  return {{"input", "rotorDiscTest.inp"}, {"mass", "rotorDiscTestMASS1.mtx"}, {"stiffness", "rotorDiscTestSTIF1.mtx"}};
}

/// A spatial scene of the rotor alone, `extra` keys merged into its body.
json rotorScene(const json& extra = json::object()) {
  json body = {{"type", "fe_body"}, {"name", "rotor"}, {"abaqus", abaqusFiles()}, {"stiffness_scale", 0.01}};
  body.update(extra);
  return {{"dimension", 3}, {"bodies", {body}}};
}

const FfrBody3d& rotorOf(const Scene& s) { return dynamic_cast<const FfrBody3d&>(s.system.body(BodyIndex(1))); }

std::string errorOf(const json& scene, const std::string& source = kSceneInDataDir) {
  return fetest::errorOf([&] { parseSceneText(scene.dump(), source); });
}

FeBodyData abaqusRotor() {
  return readAbaqusFe(kRotorDir + "/rotorDiscTest.inp", kRotorDir + "/rotorDiscTestMASS1.mtx",
                      kRotorDir + "/rotorDiscTestSTIF1.mtx");
}

}  // namespace

TEST(FeScene, SceneBodyIsTheModelsBody) {
  // The files relative to the scene's folder; the body's invariants are those of the model
  // built from the same files and options (one code path: equal to the last bit), and its
  // first mode is the published 104.63701326 Hz (with the 0.01 scale EXUDYN applies too).
  SKIP_WITHOUT_ROTOR_DATA();
  const Scene s = parseSceneText(rotorScene({{"modes", 8}}).dump(), kSceneInDataDir);
  const FfrInvariants3d& v = rotorOf(s).invariants();
  FeBodyOptions o;
  o.modes = 8;
  o.stiffnessScale = 0.01;
  const FeBodyModel m(abaqusRotor(), o, "rotor");
  ASSERT_EQ(v.numElastic(), 8);
  EXPECT_EQ(v.mass, m.invariants().mass);
  EXPECT_EQ((v.firstMoment - m.invariants().firstMoment).norm(), 0.0);
  EXPECT_EQ(MatX(v.kff - m.invariants().kff).norm(), 0.0);
  // m_ff = I (mass-normalised), K_ff = diag(omega^2): omega_1 / 2 pi = 104.63701326 Hz
  // (1e-6 relative, as test_fe_import's frequency check)
  EXPECT_LT((MatX(v.mff) - MatX::Identity(8, 8)).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(std::sqrt(v.kff.coeff(0, 0)) / (2.0 * kPi), 104.63701326, 1e-6 * 104.64);
  EXPECT_EQ(v.points.size(), 115u);  // every FE node is an attachment point
}

TEST(FeScene, PointMassAddsToMassAndMoments) {
  // A point mass m_p at node X_a: m + m_p, first moment + m_p X_a, J + m_p X_a X_a^T
  // (closed form; 1e-13 of each: sums of the same ~350 numbers in another order).
  SKIP_WITHOUT_ROTOR_DATA();
  const double mp = 0.1;
  const Vec3 Xa(0.0, 0.195984438, 0.150000006);  // node 10, on the disc's rim
  const Scene plain = parseSceneText(rotorScene().dump(), kSceneInDataDir);
  const Scene loaded =
      parseSceneText(rotorScene({{"point_masses", {{{"node", 10}, {"mass", mp}}}}}).dump(), kSceneInDataDir);
  const FfrInvariants3d &a = rotorOf(plain).invariants(), &b = rotorOf(loaded).invariants();
  EXPECT_NEAR(b.mass, a.mass + mp, 1e-13 * a.mass);
  EXPECT_LT((b.firstMoment - a.firstMoment - mp * Xa).norm(), 1e-13 * a.mass);
  EXPECT_LT((b.secondMoment - a.secondMoment - mp * Xa * Xa.transpose()).norm(), 1e-13 * a.secondMoment.norm());
  // the modes are those of the loaded body: still on its mean axes, S-bar = 0
  EXPECT_LT(b.sBar.cwiseAbs().maxCoeff(), 1e-10);
}

TEST(FeScene, ModalDampingDecaysAFreeVibrationAtZetaOmega) {
  // The rotor at rest, its first mode started with a rate: on mean axes the mode does not
  // move the frame (S-bar = 0, int rho u0~ N dV = 0), so q_1 = v0/omega_d exp(-zeta omega t)
  // sin(omega_d t), omega_d = omega sqrt(1 - zeta^2). The ratio of the envelope over five
  // periods against exp(-zeta omega 5 T): 1e-4 (rtol 1e-9 on the peaks' sampling; the
  // frame's second-order coupling is O(q^2), q ~ 1e-6).
  SKIP_WITHOUT_ROTOR_DATA();
  const double zeta = 0.02;
  json scene = rotorScene({{"modes", 2}, {"damping_ratio", zeta}, {"elastic_velocities", {1e-4, 0.0}}});
  const Scene s = parseSceneText(scene.dump(), kSceneInDataDir);
  const FfrBody3d& rotor = rotorOf(s);
  const double omega = std::sqrt(rotor.invariants().kff.coeff(0, 0));
  EXPECT_NEAR(rotor.invariants().dff.coeff(0, 0), 2.0 * zeta * omega, 1e-12 * omega);
  const double period = 2.0 * kPi / (omega * std::sqrt(1.0 - zeta * zeta));
  SolverSettings st;
  st.rtol = 1e-9;
  st.atol = 1e-14;
  st.tEnd = 5.25 * period;
  st.outputStep = period / 400.0;
  st.progress = false;
  const int oq = s.system.coordinateOffset(BodyIndex(1));
  std::vector<double> t, q1;
  const SimulationSummary r = simulate(s.system, st, [&](const OutputSample& o) {
    t.push_back(o.t);
    q1.push_back(o.q[oq + 7]);
  });
  ASSERT_TRUE(r.ok) << r.message;
  // the first and the sixth maximum, a quarter period in and five periods later
  auto peakNear = [&](double tc) {
    double best = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      if (std::abs(t[k] - tc) < 0.1 * period) best = std::max(best, q1[k]);
    }
    return best;
  };
  const double ratio = peakNear(5.25 * period - 0.0) / peakNear(0.25 * period);
  EXPECT_NEAR(ratio, std::exp(-zeta * omega * 5.0 * period), 1e-4);
  std::printf("[ figures ] modal damping zeta 0.02: five-period decay %.6f, closed form %.6f\n", ratio,
              std::exp(-zeta * omega * 5.0 * period));
}

TEST(FeScene, KeyErrorsNameTheKeyOrTheFile) {
  SKIP_WITHOUT_ROTOR_DATA();
  json both = rotorScene();
  both["bodies"][0]["ansys"] = json::object();
  expectMentions(errorOf(both), {"bodies[0]", "exactly one of \"abaqus\"", "\"ansys\""});
  json none = rotorScene();
  none["bodies"][0].erase("abaqus");
  expectMentions(errorOf(none), {"exactly one of"});
  json missing = rotorScene();
  missing["bodies"][0]["abaqus"]["mass"] = "no_such_file.mtx";
  expectMentions(errorOf(missing), {"no_such_file.mtx"});
  json badKey = rotorScene();
  badKey["bodies"][0]["abaqus"]["inputs"] = "x";
  expectMentions(errorOf(badKey), {"bodies[0]", "abaqus", "\"inputs\""});
  expectMentions(errorOf(rotorScene({{"point_masses", {{{"node", 9999}, {"mass", 1.0}}}}})),
                 {"point_masses[0]", "no node 9999"});
  expectMentions(errorOf(rotorScene({{"point_masses", {{{"node", 10}, {"mass", -1.0}}}}})),
                 {"point_masses[0]", "\"mass\"", "> 0"});
  expectMentions(errorOf(rotorScene({{"damping_ratio", 1.5}})), {"\"damping_ratio\"", "[0, 1]"});
  expectMentions(errorOf(rotorScene({{"modes", 400}})), {"body 'rotor'"});
  json planar = rotorScene();
  planar.erase("dimension");
  expectMentions(errorOf(planar), {"fe_body", "\"dimension\": 3"});
  // relative paths are relative to the scene file's folder, not the working directory
  expectMentions(errorOf(rotorScene(), "/nonexistent_folder/rotor.json"), {"/nonexistent_folder/rotorDiscTest.inp"});
}
