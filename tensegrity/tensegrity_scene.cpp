// Strict reader of tensegrity scenes (docs/tensegrity.md), in the manner of scene/scene.cpp:
// every object is checked for unknown keys first, every number for type and
// finiteness, every node name against the nodes defined.
#include "tensegrity/tensegrity_scene.hpp"

#include "scene/json_reader.hpp"
#include "scene/scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "tensegrity/self_equilibrium.hpp"

namespace flexmbd {
namespace {

using nlohmann::json;

using namespace jsonread;

/// Objects of tensegrity scenes carry their name in error locations and take
/// non-empty strings only.
class Reader : public ObjectReader {
 public:
  Reader(const json& j, std::string where) : ObjectReader(j, std::move(where)) { peekName(); }
  std::string string(const std::string& k) const { return nonEmptyString(k); }
  std::string string(const std::string& k, const std::string& fallback) const {
    return has(k) ? nonEmptyString(k) : fallback;
  }
};


int lookupNode(const TensegrityStructure& s, const std::string& name, const Reader& r) {
  const int i = s.findNode(name);
  if (i < 0) r.fail("unknown node " + inQuotes(name));
  return i;
}

std::pair<int, int> nodePair(const TensegrityStructure& s, const Reader& r) {
  const json& v = r.required("nodes");
  if (!v.is_array() || v.size() != 2 || !v[0].is_string() || !v[1].is_string()) {
    r.fail("key \"nodes\" must be two node names [\"a\", \"b\"], got " + describe(v));
  }
  return {lookupNode(s, v[0].get<std::string>(), r), lookupNode(s, v[1].get<std::string>(), r)};
}

/// The nodes (key "nodes", at least one).
void readNodes(const Reader& top, TensegrityStructure& s, int d) {
  const json& nodes = top.array("nodes");
  if (nodes.empty()) top.fail("key \"nodes\" must be a non-empty array of nodes");
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    Reader r(nodes[k], "nodes[" + std::to_string(k) + "]");
    r.allowOnly(scenekeys::kTensegrityNode);
    const std::string name = r.name("name");
    const VecX x = r.vector("position", d);
    const VecX v = r.has("velocity") ? r.vector("velocity", d) : VecX::Zero(d);
    const double m = r.nonNegative("mass", 0.0);
    std::vector<bool> fixed(d, false);
    if (r.has("fixed")) {
      const json& f = r.required("fixed");
      if (f.is_boolean()) {
        fixed.assign(d, f.get<bool>());
      } else if (f.is_array() && static_cast<int>(f.size()) == d &&
                 std::all_of(f.begin(), f.end(), [](const json& b) { return b.is_boolean(); })) {
        for (int a = 0; a < d; ++a) fixed[a] = f[a].get<bool>();
      } else {
        r.fail("key \"fixed\" must be true, false or one flag per axis, got " + describe(f));
      }
    }
    located(r.where(), [&] { return s.addNode(name, x, m, fixed, v); });
  }
}

/// The struts, cables and loads; a member without "natural_length" takes its length at x0.
void readMembersAndLoads(const Reader& top, TensegrityStructure& s, int d, const VecX& x0) {
  auto initialLength = [&](std::pair<int, int> n) {
    return (x0.segment(d * n.first, d) - x0.segment(d * n.second, d)).norm();
  };

  const json& struts = top.array("struts");
  for (std::size_t k = 0; k < struts.size(); ++k) {
    Reader r(struts[k], "struts[" + std::to_string(k) + "]");
    r.allowOnly(scenekeys::kStrut);
    const std::string name = r.name("name");
    const auto n = nodePair(s, r);
    const double ea = r.positive("EA");
    const double l0 = r.has("natural_length") ? r.number("natural_length") : initialLength(n);
    const double m = r.nonNegative("mass", 0.0);
    const std::string model = r.string("mass_model", "lumped");
    if (model != "lumped" && model != "consistent") {
      r.fail("key \"mass_model\" must be \"lumped\" or \"consistent\", got " + inQuotes(model));
    }
    const double radius = r.nonNegative("radius", 0.0);
    located(r.where(), [&] {
      return s.addStrut(name, n.first, n.second, ea, l0, m,
                        model == "lumped" ? BarMassModel::Lumped : BarMassModel::Consistent, radius);
    });
  }
  const json& cables = top.array("cables");
  for (std::size_t k = 0; k < cables.size(); ++k) {
    Reader r(cables[k], "cables[" + std::to_string(k) + "]");
    r.allowOnly(scenekeys::kCable);
    const std::string name = r.name("name");
    const auto n = nodePair(s, r);
    const bool inextensible = r.boolean("inextensible", false);
    if (inextensible && r.has("EA")) r.fail("an inextensible cable takes no \"EA\"");
    const double ea = inextensible ? 0.0 : r.positive("EA");
    const double l0 = r.has("natural_length") ? r.number("natural_length") : initialLength(n);
    const double radius = r.nonNegative("radius", 0.0);
    located(r.where(), [&] { return s.addCable(name, n.first, n.second, ea, l0, inextensible, radius); });
  }
  const json& loads = top.array("loads");
  for (std::size_t k = 0; k < loads.size(); ++k) {
    Reader r(loads[k], "loads[" + std::to_string(k) + "]");
    r.allowOnly(scenekeys::kLoad);
    const std::string name = r.name("name", "load" + std::to_string(k));
    const int node = lookupNode(s, r.name("node"), r);
    const json& f = r.required("force");
    if (!f.is_array() || static_cast<int>(f.size()) != d) {
      r.fail("key \"force\" must be an array of " + std::to_string(d) + " laws (or null), got " + describe(f));
    }
    std::vector<TimeLawPtr> comps(d);
    for (int a = 0; a < d; ++a) {
      if (!f[a].is_null()) comps[a] = parseTimeLaw(f[a], r.where() + ".force[" + std::to_string(a) + "]");
    }
    located(r.where(), [&] { s.addLoad(name, node, comps); });
  }
}

/// The prestress of the finalized structure: its one self-stress state scaled to the tension of one cable.
void readPrestress(const Reader& top, TensegrityStructure& s, int d, const VecX& x0) {
  Reader r(top.required("prestress"), "prestress");
  r.allowOnly(scenekeys::kPrestress);
  const std::string cableName = r.name("cable");
  const double tension = r.positive("tension");
  const SelfStressStates st = computeSelfStress(s, s.initialPositions());
  if (st.forceDensities.cols() != 1) {
    r.fail("the structure has " + std::to_string(st.forceDensities.cols()) +
           " independent self-stress states (expected exactly 1 to prestress from)");
  }
  int member = -1;
  for (int c = 0; c < s.numCables(); ++c) {
    if (s.cable(c).name == cableName) member = s.numStruts() + c;
  }
  if (member < 0) r.fail("unknown cable " + inQuotes(cableName));
  VecX qd = st.forceDensities.col(0);
  const auto [ni, nj] = s.memberNodes({false, member - s.numStruts()});
  const double l = (x0.segment(d * ni, d) - x0.segment(d * nj, d)).norm();
  if (std::abs(qd[member]) < 1e-12) {
    r.fail("cable " + inQuotes(cableName) + " carries no force in the self-stress state");
  }
  qd *= tension / (qd[member] * l);  // force of the reference cable: q l = tension
  located(r.where(), [&] { applyPrestress(s, qd, 1.0); });
}

/// The solver object: the settings of the time stepper or of the massless-cable integrator, checked by
/// constructing it.
void readSolver(const Reader& top, const TensegrityStructure& s, TensegrityScene& scene) {
  Reader sv(top.required("solver"), "solver");
  const std::string method = sv.string("method");
  if (method == "time_stepping") {
    sv.allowOnly(scenekeys::kTimeSteppingSolver, " for method time_stepping");
    scene.method = TensegrityScene::Method::TimeStepping;
    TimeSteppingSettings& o = scene.timeStepping;
    o.tStart = sv.number("t_start", 0.0);
    o.tEnd = sv.number("t_end");
    o.timeStep = sv.positive("time_step");
    o.outputStep = sv.nonNegative("output_step", 0.0);
    o.lcp.method = located(sv.where(), [&] { return parseLcpMethod(sv.string("lcp", "lemke")); });
    o.lcp.tolerance = sv.positive("lcp_tolerance", 1e-10);
    o.lcp.maxIterations = static_cast<int>(sv.integer("lcp_max_iterations", 100000, 1));
    o.projectPositions = sv.boolean("projection", true);
    o.projectionTolerance = sv.positive("projection_tolerance", 1e-12);
    o.slackTolerance = sv.nonNegative("slack_tolerance", 1e-9);
    o.detectContacts = sv.boolean("contacts", false);
    o.contactConstraints = sv.boolean("contact_constraints", false);
    if (!(o.tEnd > o.tStart)) sv.fail("key \"t_end\" must be > t_start, got " + fmt(o.tEnd));
    located(sv.where(), [&] { return TensegrityTimeStepper(s, o), 0; });
  } else if (method == "massless_cables") {
    sv.allowOnly(scenekeys::kMasslessCablesSolver, " for method massless_cables");
    scene.method = TensegrityScene::Method::MasslessCables;
    MasslessCableSettings& o = scene.massless;
    o.tStart = sv.number("t_start", 0.0);
    o.tEnd = sv.number("t_end");
    o.outputStep = sv.positive("output_step");
    o.cvode.rtol = sv.positive("rtol", 1e-10);
    o.cvode.atol = sv.positive("atol", 1e-12);
    o.cvode.maxStepSize = sv.nonNegative("max_step", 0.0);
    o.slackTolerance = sv.nonNegative("slack_tolerance", 1e-9);
    o.detectContacts = sv.boolean("contacts", false);
    if (!(o.tEnd > o.tStart)) sv.fail("key \"t_end\" must be > t_start, got " + fmt(o.tEnd));
    located(sv.where(), [&] { return MasslessCableIntegrator(s, o), 0; });
  } else {
    sv.fail("unknown method " + inQuotes(method) + " (expected one of: time_stepping, massless_cables)");
  }
}

}  // namespace

bool isTensegritySceneFile(const std::string& path) {
  std::string text;
  try {
    text = readSceneFile(path);
    checkJsonNesting(text, path);
  } catch (const InputError&) {
    return false;  // the scene loader reports it
  }
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return false;
  const auto it = j.find("model");
  return it != j.end() && it->is_string() && it->get<std::string>() == "tensegrity";
}

TensegrityScene loadTensegrityScene(const std::string& path) {
  const std::string text = readSceneFile(path);
  checkJsonNesting(text, path);
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  } catch (const json::exception& e) {
    // 406: a number literal that does not fit a double (1e999)
    throw InputError(path + ": invalid JSON: " + plainMessage(e) + " (numbers must be finite)");
  }
  try {
    return parseTensegrityScene(j);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

TensegrityScene parseTensegrityScene(const json& j) {
  Reader top(j, "scene");
  top.allowOnly(scenekeys::kTensegrityScene);
  if (top.string("model") != "tensegrity") top.fail("key \"model\" must be \"tensegrity\"");
  TensegrityScene scene;
  scene.name = top.string("name", "");
  const long dim = top.integer("dimension", 3, 2);
  if (dim != 2 && dim != 3) top.fail("key \"dimension\" must be 2 or 3, got " + std::to_string(dim));
  const int d = static_cast<int>(dim);
  scene.structure = std::make_unique<TensegrityStructure>(d);
  TensegrityStructure& s = *scene.structure;
  if (top.has("gravity")) s.setGravity(top.vector("gravity", d));
  if (top.has("max_struts_per_node")) s.setMaxStrutsPerNode(static_cast<int>(top.integer("max_struts_per_node", 1, 1)));

  readNodes(top, s, d);
  const VecX x0 = s.initialPositions();
  readMembersAndLoads(top, s, d, x0);
  s.finalize();

  if (top.has("prestress")) readPrestress(top, s, d, x0);

  readSolver(top, s, scene);
  checkTensegrityTimes(scene);
  return scene;
}

void checkTensegrityTimes(const TensegrityScene& scene) {
  const bool stepping = scene.method == TensegrityScene::Method::TimeStepping;
  const double t0 = stepping ? scene.timeStepping.tStart : scene.massless.tStart;
  const double t1 = stepping ? scene.timeStepping.tEnd : scene.massless.tEnd;
  if (!resolvableTimeSpan(t0, t1)) {
    throw InputError("solver: key \"t_end\" must give " + std::string(kTimeSpanRule) + ", got t_end = " + fmt(t1) +
                     " with t_start = " + fmt(t0));
  }
}

}  // namespace flexmbd
