#include "scene/flexible_body_reader.hpp"

#include <algorithm>
#include <string>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_options.hpp"
#include "scene/scene_keys.hpp"

namespace flexmbd::scenereaders {

using nlohmann::json;
using namespace jsonread;

namespace {

/// Most elastic modes of a modal body (the same bound on its coordinates).
constexpr long kMaxModes = 3000;

/// An optional point key [x, y] or [x, y, z] of the mesh's dimension.
template <class Point>
Point readPoint(const ObjectReader& r, const std::string& key, const Point& fallback) {
  if constexpr (Point::RowsAtCompileTime == 2) {
    return r.vec2(key, fallback);
  } else {
    return r.has(key) ? Point(r.vector(key, 3)) : fallback;
  }
}

/// A straight mesh of `n` elements like `element` (planar; spatial with its y axis hint).
BeamMesh2d straightMesh(double length, int n, const BeamMesh2d::Element& element, const Vec2& origin) {
  return BeamMesh2d::straight(length, n, element.section, origin);
}
BeamMesh3d straightMesh(double length, int n, const BeamMesh3d::Element& element, const Vec3& origin) {
  return BeamMesh3d::straight(length, n, element.section, origin, element.yHint);
}

}  // namespace

std::pair<std::string, std::string> readBodyTypeAndName(ObjectReader& r) {
  r.peekName();
  std::string type = readType(r, "body", {"rigid", "flexible", "flexible_invariants", "fe_body", "sid_body"});
  std::string name = r.name("name");
  if (name == "ground") {
    r.fail("the name \"ground\" is reserved for the fixed ground body (it exists in every scene; refer to it "
           "in joints, do not define it)");
  }
  return {std::move(type), std::move(name)};
}

template <class Mesh>
Mesh readBeamMesh(const ObjectReader& r, const typename Mesh::Element& element, const std::vector<std::string>& beamKeys,
                  const std::string& beamContext) {
  using Point = typename decltype(Mesh::nodes)::value_type;
  constexpr int dim = Point::RowsAtCompileTime;
  const char* const pointForm = dim == 2 ? "[[x, y], ...]" : "[[x, y, z], ...]";
  if (r.has("beam")) {
    if (r.has("nodes") || r.has("elements")) r.fail("give either \"beam\" or \"nodes\" and \"elements\", not both");
    const ObjectReader b(r.object("beam"), r.where() + ": beam");
    b.allowOnly(beamKeys, beamContext);
    const double length = b.positive("length");
    const int n = static_cast<int>(b.integer("elements", 1, 1, kMaxElements));
    const Point origin = readPoint(b, "origin", Point(Point::Zero()));
    return located(b.where(), [&] { return straightMesh(length, n, element, origin); });
  }
  Mesh mesh;
  const MatX nodes = r.matrix("nodes");
  if (nodes.cols() != dim || nodes.rows() < 2) r.fail(std::string("key \"nodes\" must list at least two points ") + pointForm);
  for (int i = 0; i < nodes.rows(); ++i) mesh.nodes.push_back(nodes.row(i).transpose());
  const json& els = r.required("elements");
  if (!els.is_array() || els.empty()) r.fail("key \"elements\" must be a non-empty array of node pairs [[i, j], ...]");
  if (static_cast<long>(els.size()) > kMaxElements) {
    r.fail("key \"elements\" lists " + std::to_string(els.size()) + " elements; at most " +
           std::to_string(kMaxElements) + " per body");
  }
  for (std::size_t e = 0; e < els.size(); ++e) {
    const std::string label = "elements[" + std::to_string(e) + "]";
    if (!els[e].is_array() || els[e].size() != 2) {
      r.fail("key " + inQuotes(label) + " must be a node pair [i, j], got " + describe(els[e]));
    }
    typename Mesh::Element el = element;
    el.node1 = r.index(els[e][0], label + "[0]");
    el.node2 = r.index(els[e][1], label + "[1]");
    mesh.elements.push_back(el);
  }
  return mesh;
}

template BeamMesh2d readBeamMesh<BeamMesh2d>(const ObjectReader&, const BeamMesh2d::Element&,
                                             const std::vector<std::string>&, const std::string&);
template BeamMesh3d readBeamMesh<BeamMesh3d>(const ObjectReader&, const BeamMesh3d::Element&,
                                             const std::vector<std::string>&, const std::string&);

VecX readElasticState(const ObjectReader& r, const char* key, int n) {
  if (!r.has(key)) return VecX::Zero(n);
  const VecX v = r.vector(key);
  if (v.size() != n) {
    r.fail("key " + inQuotes(key) + " must list " + std::to_string(n) +
           " numbers (one per elastic coordinate of this body), got " + std::to_string(v.size()));
  }
  return v;
}

MatX sizedMatrix(const ObjectReader& iv, const char* key, const MatX& m, int rows, int cols, int nf) {
  if (m.rows() != rows || m.cols() != cols) {
    iv.fail("key " + inQuotes(key) + " must be a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix (" +
            std::to_string(nf) + " elastic coordinates, from m_ff), got " + std::to_string(m.rows()) + " x " +
            std::to_string(m.cols()));
  }
  return m;
}

MatX readSizedMatrix(const ObjectReader& iv, const char* key, int rows, int cols, int nf) {
  return sizedMatrix(iv, key, iv.matrix(key), rows, cols, nf);
}

SpMat readSquareInvariant(const ObjectReader& iv, const char* key, int nf, bool optional) {
  if (optional && !iv.has(key)) return SpMat(nf, nf);
  return readSizedMatrix(iv, key, nf, nf, nf).sparseView(1.0, 0.0);
}

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
  // the elements' beam theory (BeamTheory; the key lists admit it for spatial bodies only so far)
  const std::string theory = r.string("beam_theory", "euler_bernoulli");
  if (theory == "rayleigh") {
    o.theory = BeamTheory::Rayleigh;
  } else if (theory == "timoshenko") {
    o.theory = BeamTheory::Timoshenko;
  } else if (theory != "euler_bernoulli") {
    r.fail("key \"beam_theory\" must be \"euler_bernoulli\", \"rayleigh\" or \"timoshenko\", got " +
           inQuotes(theory));
  }
  o.inertiaModes = r.boolean("inertia_modes", false);
  if (o.inertiaModes && !craigBampton && o.modes == 0 && o.modeSet.empty()) {
    r.fail("key \"inertia_modes\" needs a modal reduction (\"modes\", or \"reduction\": \"craig_bampton\")");
  }
}

template void readBeamModelOptions<FfrBeamOptions>(const ObjectReader&, int, FfrBeamOptions&);
template void readBeamModelOptions<FfrBeamOptions3d>(const ObjectReader&, int, FfrBeamOptions3d&);

}  // namespace flexmbd::scenereaders
