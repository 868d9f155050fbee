#include "builders/component_kinds.hpp"

#include "joints/point_in_plane_joint.hpp"
#include "joints/point_on_line_joint.hpp"

namespace flexmbd {

const std::vector<ComponentKind>& componentKinds() {
  // One registration line per kind: its declaration, defined in the kind's own file.
  static const std::vector<ComponentKind> kinds = {
      pointOnLineJointKind(),
      pointInPlaneJointKind(),
  };
  return kinds;
}

const ComponentKind* findComponentKind(const std::string& section, const std::string& type) {
  for (const ComponentKind& k : componentKinds()) {
    if (k.section == section && k.type == type) return &k;
  }
  return nullptr;
}

}  // namespace flexmbd
