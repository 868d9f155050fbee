#include "scene/fe_body_reader.hpp"

#include <array>
#include <filesystem>
#include <limits>

#include "bodies/fe_stress.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "fe_import/fe_ansys.hpp"
#include "fe_import/fe_calculix.hpp"
#include "scene/scene_keys.hpp"

namespace flexmbd::scenereaders {

using jsonread::inQuotes;
using jsonread::located;
using jsonread::json;
using jsonread::ObjectReader;

std::string filePath(const ObjectReader& files, const std::string& key, const std::string& baseDir) {
  const std::filesystem::path p(files.nonEmptyString(key));
  if (p.is_absolute() || baseDir.empty()) return p.string();
  return (std::filesystem::path(baseDir) / p).string();
}

FeBodyData readFeBodyFiles(const ObjectReader& r, const std::string& baseDir) {
  static const std::array<const char*, 3> kFormats = {"abaqus", "ansys", "calculix"};
  int given = 0;
  for (const char* f : kFormats) given += r.has(f) ? 1 : 0;
  if (given != 1) {
    r.fail("give exactly one of \"abaqus\" {\"input\", \"mass\", \"stiffness\"}, \"ansys\" {\"coordinates\", "
           "\"elements\", \"dof_map\", \"mass\", \"stiffness\"} or \"calculix\" {\"job\"}: the files of the FE export");
  }
  if (r.has("abaqus")) {
    const ObjectReader f(r.object("abaqus"), r.where() + ".abaqus");
    f.allowOnly(scenekeys::kFeFilesAbaqus, " for Abaqus files");
    return readAbaqusFe(filePath(f, "input", baseDir), filePath(f, "mass", baseDir), filePath(f, "stiffness", baseDir));
  }
  if (r.has("calculix")) {
    const ObjectReader f(r.object("calculix"), r.where() + ".calculix");
    f.allowOnly(scenekeys::kFeFilesCalculix, " for CalculiX files");
    return readCalculixFe(CalculixFeFiles::ofJob(filePath(f, "job", baseDir)));
  }
  const ObjectReader f(r.object("ansys"), r.where() + ".ansys");
  f.allowOnly(scenekeys::kFeFilesAnsys, " for Ansys files");
  AnsysFeFiles files;
  files.coordinates = filePath(f, "coordinates", baseDir);
  files.elements = filePath(f, "elements", baseDir);
  files.dofMap = filePath(f, "dof_map", baseDir);
  files.mass = filePath(f, "mass", baseDir);
  files.stiffness = filePath(f, "stiffness", baseDir);
  return readAnsysFe(files);
}

/// Key "spin_stiffening" of `r`: {"calculix": {"job"} or "abaqus": {"stiffness"}, "spin":
/// [wx, wy, wz]}.
FeSpinStiffening readSpinStiffening(const ObjectReader& r, const FeBodyData& data, const std::string& baseDir) {
  const ObjectReader st(r.object("spin_stiffening"), r.where() + ".spin_stiffening");
  st.allowOnly(scenekeys::kFeSpinStiffening, " for spin_stiffening");
  if (st.has("calculix") == st.has("abaqus")) {
    st.fail("give exactly one of \"calculix\" {\"job\"} or \"abaqus\" {\"stiffness\"}: the preloaded stiffness "
            "exported by the FE code (docs/fe-import.md, \"Spin stiffening\")");
  }
  FeSpinStiffening out;
  out.spin = st.vector("spin", 3);
  if (!(out.spin.norm() > 0.0)) st.fail("key \"spin\" must be the spin of the preload run (rad/s), not zero");
  if (st.has("abaqus")) {
    const ObjectReader f(st.object("abaqus"), st.where() + ".abaqus");
    f.allowOnly(scenekeys::kFeSpinAbaqus, " for an Abaqus preloaded stiffness");
    const std::string path = filePath(f, "stiffness", baseDir);
    out.preloadedStiffness =
        located(f.where(), [&] { return readAbaqusPreloadedStiffness(path, data, out.heldDofs); });
    return out;
  }
  const ObjectReader f(st.object("calculix"), st.where() + ".calculix");
  f.allowOnly(scenekeys::kFeFilesCalculix, " for CalculiX files");
  const std::string job = filePath(f, "job", baseDir);
  out.preloadedStiffness =
      located(f.where(), [&] { return readCalculixPreloadedStiffness(CalculixFeFiles::ofJob(job), data, out.heldDofs); });
  return out;
}

FeBodyOptions readFeBodyOptions(const ObjectReader& r, const FeBodyData& data, const std::string& baseDir) {
  FeBodyOptions o;
  o.modes = static_cast<int>(r.integer("modes", o.modes, 1));
  o.stiffnessScale = r.positive("stiffness_scale", 1.0);
  o.dampingRatio = r.nonNegative("damping_ratio", 0.0);
  if (o.dampingRatio > 1.0) r.fail("key \"damping_ratio\" must be in [0, 1], got " + fmt(o.dampingRatio));
  o.inertiaModes = r.boolean("inertia_modes", false);
  if (r.has("spin_stiffening")) o.spinStiffening = readSpinStiffening(r, data, baseDir);
  const json& masses = r.array("point_masses");
  for (std::size_t k = 0; k < masses.size(); ++k) {
    const ObjectReader p(masses[k], r.where() + ".point_masses[" + std::to_string(k) + "]");
    p.allowOnly(scenekeys::kFePointMass, " for a point mass");
    if (!p.has("node")) p.fail("missing required key \"node\" (the FE code's node number)");
    const long id = p.integer("node", 0, std::numeric_limits<int>::min());
    const int a = data.nodeIndex(static_cast<int>(id));
    if (a < 0) p.fail("key \"node\": the mesh of " + data.source + " has no node " + std::to_string(id));
    o.pointMasses.push_back({a, p.positive("mass")});
  }
  const json& interfaces = r.array("interfaces");
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    const ObjectReader f(interfaces[k], r.where() + ".interfaces[" + std::to_string(k) + "]");
    f.allowOnly(scenekeys::kFeInterface, " for an interface");
    FeInterface i;
    i.name = f.name("name");
    const std::string kind = f.string("kind", "averaging");
    if (kind != "rigid" && kind != "averaging") {
      f.fail("key \"kind\" must be \"rigid\" (RBE2: the nodes move rigidly with the frame) or \"averaging\" "
             "(RBE3: the frame follows their mean motion), got " + inQuotes(kind));
    }
    i.kind = kind == "rigid" ? FeInterfaceKind::Rigid : FeInterfaceKind::Averaging;
    if (f.has("nodes") == f.has("node_set")) {
      f.fail("give exactly one of \"nodes\" [FE node numbers] or \"node_set\" (a node set of the export)");
    }
    if (f.has("node_set")) {
      const std::string set = f.nonEmptyString("node_set");
      const auto it = data.nodeSets.find(set);
      if (it == data.nodeSets.end()) {
        std::string known;
        for (const auto& [n, nodes] : data.nodeSets) known += (known.empty() ? "" : ", ") + n;
        f.fail("key \"node_set\": " + data.source + " has no node set " + inQuotes(set) + " (it has: " +
               (known.empty() ? std::string("none") : known) + ")");
      }
      i.nodes = it->second;
    } else {
      const json& ids = f.requiredArray("nodes");
      for (std::size_t n = 0; n < ids.size(); ++n) {
        const int id = f.index(ids[n], "nodes[" + std::to_string(n) + "]");
        const int a = data.nodeIndex(id);
        if (a < 0) f.fail("key \"nodes\": the mesh of " + data.source + " has no node " + std::to_string(id));
        i.nodes.push_back(a);
      }
    }
    if (f.has("point")) {
      i.atCentroid = false;
      i.point = f.vector("point", 3);
    }
    o.interfaces.push_back(std::move(i));
  }
  const std::string reduction = r.string("reduction", "free_free");
  if (reduction != "free_free" && reduction != "craig_bampton") {
    r.fail("key \"reduction\" must be \"free_free\" (normal modes on mean axes) or \"craig_bampton\" (the frame on "
           "the rigid interface \"reference\"), got " + inQuotes(reduction));
  }
  if ((reduction == "craig_bampton") != r.has("reference")) {
    r.fail("key \"reference\" (the rigid interface the frame follows) goes with \"reduction\": \"craig_bampton\", and "
           "only with it");
  }
  if (reduction == "craig_bampton") {
    o.reduction = FeReduction::CraigBampton;
    o.reference = r.nonEmptyString("reference");
  }
  return o;
}

MatX readFeStressShapes(const ObjectReader& r, const FeBodyData& data, const FeBodyModel& model,
                        const std::string& baseDir, const std::string& owner) {
  const ObjectReader st(r.object("stresses"), r.where() + ".stresses");
  st.allowOnly(scenekeys::kFeStresses, " for stresses");
  const json& files = st.requiredArray("calculix_frd");
  if (files.empty()) st.fail("key \"calculix_frd\" must list at least one .frd file");
  FeStressSamples samples;
  for (std::size_t k = 0; k < files.size(); ++k) {
    if (!files[k].is_string() || files[k].get<std::string>().empty()) {
      st.fail("key \"calculix_frd\": entry " + std::to_string(k) + " must be a file path (a string)");
    }
    std::filesystem::path p(files[k].get<std::string>());
    if (!p.is_absolute() && !baseDir.empty()) p = std::filesystem::path(baseDir) / p;
    const FeStressSamples s = stressSamplesFromFrd(readCalculixFrd(p.string()), data, p.string(), owner);
    samples = k == 0 ? s : joinedSamples(samples, s);
  }
  return located(st.where(), [&] { return stressShapes(model, samples, owner); });
}

}  // namespace flexmbd::scenereaders
