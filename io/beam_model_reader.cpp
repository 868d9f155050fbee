#include "io/beam_model_reader.hpp"

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
  if (r.has("modes")) {
    const json& m = r.required("modes");
    if (m.is_array()) {
      for (std::size_t k = 0; k < m.size(); ++k) o.modeSet.push_back(r.index(m[k], "modes[" + std::to_string(k) + "]"));
      if (o.modeSet.empty()) r.fail("key \"modes\" must list at least one mode");
    } else {
      o.modes = static_cast<int>(r.integer("modes", 0, 1, kMaxModes));
    }
  }
  o.geometricStiffening = r.boolean("geometric_stiffening", false);
}

template void readBeamModelOptions<FfrBeamOptions>(const ObjectReader&, int, FfrBeamOptions&);
template void readBeamModelOptions<FfrBeamOptions3d>(const ObjectReader&, int, FfrBeamOptions3d&);

}  // namespace flexmbd::scenereaders
