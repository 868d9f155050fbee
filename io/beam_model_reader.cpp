#include "io/beam_model_reader.hpp"

#include <algorithm>
#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "io/scene_keys.hpp"

namespace flexmbd::scenereaders {

using nlohmann::json;
using namespace jsonread;

namespace {
/// Most elastic modes of a modal body (the same bound on its coordinates).
constexpr long kMaxModes = 3000;
}  // namespace

template <class Options>
void readBeamModelOptions(const ObjectReader& r, int numNodes, Options& o) {
  using Type = decltype(o.reference.type);
  const ObjectReader ref(r.object("reference"), r.where() + ": reference");
  const std::string type = ref.string("type");
  if (type == "pinned_pinned") {
    ref.allowOnly(scenekeys::kReferencePinnedPinned, " for pinned_pinned");
    o.reference.type = Type::PinnedPinned;
    o.reference.nodeA = 0;
    o.reference.nodeB = numNodes - 1;
    if (ref.has("nodes")) {
      const json& n = ref.required("nodes");
      if (!n.is_array() || n.size() != 2) ref.fail("key \"nodes\" must be two node indices [A, B], got " + describe(n));
      o.reference.nodeA = ref.index(n[0], "nodes[0]");
      o.reference.nodeB = ref.index(n[1], "nodes[1]");
    }
  } else if (type == "clamped") {
    ref.allowOnly(scenekeys::kReferenceClamped, " for clamped");
    o.reference.type = Type::Clamped;
    o.reference.nodeA = static_cast<int>(ref.integer("node", 0, 0));
  } else if (type == "free_free") {
    ref.allowOnly(scenekeys::kReferenceFreeFree, " for free_free");
    o.reference.type = Type::FreeFree;
  } else {
    ref.fail("unknown reference type " + inQuotes(type) + " (expected one of: pinned_pinned, clamped, free_free)");
  }
  // "reduction": "normal" (default) or "craig_bampton" with its "interface_nodes" (the
  // keys are allowed where the body's key list has them: planar bodies so far)
  const std::string reduction = r.string("reduction", "normal");
  if (reduction == "craig_bampton") {
    o.reduction = ModalReduction::CraigBampton;
    if (!r.has("interface_nodes")) r.fail("missing required key \"interface_nodes\" (with \"reduction\": \"craig_bampton\")");
    const json& n = r.required("interface_nodes");
    if (!n.is_array() || n.empty()) {
      r.fail("key \"interface_nodes\" must be a non-empty array of node indices [i, ...], got " + describe(n));
    }
    for (std::size_t k = 0; k < n.size(); ++k) {
      const std::string label = "interface_nodes[" + std::to_string(k) + "]";
      const int node = r.index(n[k], label);
      if (node >= numNodes) {
        r.fail("key " + inQuotes(label) + ": node " + std::to_string(node) + " does not exist (nodes 0.." +
               std::to_string(numNodes - 1) + ")");
      }
      if (std::find(o.interfaceNodes.begin(), o.interfaceNodes.end(), node) != o.interfaceNodes.end()) {
        r.fail("key " + inQuotes(label) + ": node " + std::to_string(node) + " is listed twice");
      }
      o.interfaceNodes.push_back(node);
    }
  } else if (reduction != "normal") {
    r.fail("key \"reduction\" must be \"normal\" or \"craig_bampton\", got " + inQuotes(reduction));
  } else if (r.has("interface_nodes")) {
    r.fail("key \"interface_nodes\" is only allowed with \"reduction\": \"craig_bampton\"");
  }
  const bool craigBampton = o.reduction == ModalReduction::CraigBampton;
  if (r.has("modes")) {
    const json& m = r.required("modes");
    if (m.is_array()) {
      for (std::size_t k = 0; k < m.size(); ++k) o.modeSet.push_back(r.index(m[k], "modes[" + std::to_string(k) + "]"));
      if (o.modeSet.empty()) r.fail("key \"modes\" must list at least one mode");
    } else {
      // Craig-Bampton: the fixed-interface modes, 0 (static condensation only) allowed
      o.modes = static_cast<int>(r.integer("modes", 0, craigBampton ? 0 : 1, kMaxModes));
    }
  }
  o.geometricStiffening = r.boolean("geometric_stiffening", false);
  if constexpr (std::is_same_v<Options, FfrBeamOptions3d>) {
    // the spatial element's beam theory (BeamTheory; the key list admits it for spatial bodies only)
    const std::string theory = r.string("beam_theory", "euler_bernoulli");
    if (theory == "rayleigh") {
      o.theory = BeamTheory::Rayleigh;
    } else if (theory == "timoshenko") {
      o.theory = BeamTheory::Timoshenko;
    } else if (theory != "euler_bernoulli") {
      r.fail("key \"beam_theory\" must be \"euler_bernoulli\", \"rayleigh\" or \"timoshenko\", got " +
             inQuotes(theory));
    }
  }
  o.inertiaModes = r.boolean("inertia_modes", false);
  if (o.inertiaModes && !craigBampton && o.modes == 0 && o.modeSet.empty()) {
    r.fail("key \"inertia_modes\" needs a modal reduction (\"modes\", or \"reduction\": \"craig_bampton\")");
  }
}

template void readBeamModelOptions<FfrBeamOptions>(const ObjectReader&, int, FfrBeamOptions&);
template void readBeamModelOptions<FfrBeamOptions3d>(const ObjectReader&, int, FfrBeamOptions3d&);

}  // namespace flexmbd::scenereaders
