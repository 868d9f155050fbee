#include "scene/component_reader.hpp"

#include <nlohmann/json.hpp>

#include "builders/component_kinds.hpp"
#include "core/errors.hpp"
#include "scene/spatial_scene.hpp"

namespace flexmbd::scenereaders {

namespace {

using jsonread::ObjectReader;

const char* dimensionsText(KindDimensions d) {
  switch (d) {
    case KindDimensions::Planar: return "planar";
    case KindDimensions::Spatial: return "spatial";
    case KindDimensions::Both: return "planar and spatial";
  }
  return "";
}

/// The singular of a section's name in messages and method names: "joints" -> "joint".
std::string singular(const std::string& section) { return section.substr(0, section.size() - 1); }

/// A kind's values read from a scene object, checked against its declaration.
class SceneArgs final : public ComponentArgs {
 public:
  SceneArgs(const ComponentKind& kind, int dimension, const ObjectReader& r, const System& sys)
      : kind_(kind), dimension_(dimension), r_(r), sys_(sys) {
    std::vector<std::string> allowed = {"name", "type"};
    for (const KeySpec& k : kind.keys) allowed.push_back(k.name);
    r.allowOnly(allowed, " for a " + kind.type + " " + singular(kind.section));
    name_ = r.name("name");
    for (const KeySpec& k : kind.keys) {
      if (!r.has(k.name)) {
        r.fail("missing key " + jsonread::inQuotes(k.name) + " of a " + kind.type + " " + singular(kind.section) +
               " (" + k.description + ")");
      }
    }
  }
  int dimension() const override { return dimension_; }
  const std::string& name() const override { return name_; }
  std::array<BodyIndex, 2> bodyPair(const std::string& key) const override {
    spec(key, KeyType::BodyPair);
    return lookupBodyPair(sys_, r_, "a " + kind_.type + " " + singular(kind_.section));
  }
  std::array<Vec3, 2> pointPair(const std::string& key) const override {
    spec(key, KeyType::PointPair);
    if (dimension_ == 2) {
      const auto p = r_.pointPair(key);
      return {lift(p[0]), lift(p[1])};
    }
    const MatX m = r_.matrix(key);
    if (m.rows() != 2 || m.cols() != 3) {
      r_.fail("key " + jsonread::inQuotes(key) + " must be two points [[xi, yi, zi], [xj, yj, zj]]");
    }
    return {Vec3(m.row(0).transpose()), Vec3(m.row(1).transpose())};
  }
  Vec3 direction(const std::string& key) const override {
    spec(key, KeyType::Direction);
    const VecX d = r_.direction(key, dimension_);
    const Vec3 v = dimension_ == 2 ? Vec3(d[0], d[1], 0.0) : Vec3(d[0], d[1], d[2]);
    return v.normalized();
  }

 private:
  /// The declaration of `key`; a kind's build that reads a key it did not declare, or
  /// as another type, is a programming error.
  const KeySpec& spec(const std::string& key, KeyType type) const {
    for (const KeySpec& k : kind_.keys) {
      if (k.name == key && k.type == type) return k;
    }
    throw std::logic_error("the " + kind_.type + " kind reads key \"" + key + "\" that it does not declare");
  }

  const ComponentKind& kind_;
  int dimension_;
  const ObjectReader& r_;
  const System& sys_;
  std::string name_;
};

void build(const ComponentKind& kind, int dimension, const ObjectReader& r, System& sys) {
  if (!kind.allows(dimension)) {
    r.fail("a " + kind.type + " " + singular(kind.section) + " is " + dimensionsText(kind.dimensions) +
           (dimension == 2 ? ": give the scene \"dimension\": 3" : "; this scene is spatial (\"dimension\": 3)"));
  }
  const SceneArgs args(kind, dimension, r, sys);
  jsonread::located(r.where(), [&] {
    kind.build(sys, args);
    return 0;
  });
}

/// A key's value as the reference writes it, in the scenes the kind may appear in.
std::string typeText(KeyType t, KindDimensions d) {
  const auto planarOrSpatial = [d](const std::string& planar, const std::string& spatial) {
    if (d == KindDimensions::Planar) return planar;
    if (d == KindDimensions::Spatial) return spatial;
    return planar + " (spatial: " + spatial + ")";
  };
  switch (t) {
    case KeyType::BodyPair: return "[name, name]";
    case KeyType::PointPair: return planarOrSpatial("[[x, y], [x, y]]", "[[x, y, z], [x, y, z]]");
    case KeyType::Direction: return planarOrSpatial("[x, y]", "[x, y, z]") + ", not zero";
  }
  return "";
}

}  // namespace

std::vector<std::string> registeredTypes(const std::string& section, int dimension) {
  std::vector<std::string> out;
  for (const ComponentKind& k : componentKinds()) {
    if (k.section == section && k.allows(dimension)) out.push_back(k.type);
  }
  return out;
}

bool readRegisteredComponent(const std::string& section, int dimension, const ObjectReader& r, System& sys) {
  if (!r.has("type") || !r.required("type").is_string()) return false;  // the caller reports it
  const ComponentKind* kind = findComponentKind(section, r.string("type"));
  if (!kind) return false;
  build(*kind, dimension, r, sys);
  return true;
}

bool readDriverOfRegisteredJoint(const std::string& driverType, const std::string& name, ConstraintIndex joint,
                                 const ObjectReader& r, System& sys) {
  const Constraint& c = sys.constraint(joint);
  if (!findComponentKind("joints", c.typeName())) return false;
  const std::string quantity = driverType == "joint_angle" ? "angle" : "displacement";
  TimeLawPtr law = jsonread::parseTimeLaw(r.object("law"), r.where() + ".law");
  std::unique_ptr<Constraint> driver = jsonread::located(r.where(), [&] { return c.makeDriver(quantity, name, law); });
  if (!driver) {
    r.fail("a " + driverType + " driver needs a joint with " + (quantity == "angle" ? "an angle" : "a displacement") +
           " to drive, but joint " + jsonread::inQuotes(c.name()) + " (" + c.typeName() + ") has none");
  }
  jsonread::located(r.where(), [&] { return sys.addConstraint(std::move(driver)); });
  return true;
}

void addComponent(System& sys, int dimension, const std::string& section, const std::string& type,
                  const nlohmann::json& keys, const std::string& where) {
  const ComponentKind* kind = findComponentKind(section, type);
  if (!kind) throw InputError(where + ": no " + singular(section) + " type " + jsonread::inQuotes(type));
  nlohmann::json object = keys;
  object["type"] = type;
  const ObjectReader r(object, where);
  build(*kind, dimension, r, sys);
}

std::string componentReference() {
  std::string out;
  for (const ComponentKind& k : componentKinds()) {
    out += "#### `" + k.type + "` (" + k.section + ", " + dimensionsText(k.dimensions) + ")\n\n" + k.summary + "\n\n";
    out += "| key | value | unit | default | meaning |\n|---|---|---|---|---|\n";
    out += "| `name` | name | | required | The " + singular(k.section) + "'s name, unique in the scene. |\n";
    out += "| `type` | `\"" + k.type + "\"` | | required | |\n";
    for (const KeySpec& s : k.keys) {
      out += "| `" + s.name + "` | " + typeText(s.type, k.dimensions) + " | " + s.unit + " | required | " + s.description +
             " |\n";
    }
    out += "\n";
  }
  return out;
}

}  // namespace flexmbd::scenereaders
