#include "bodies/fe_body_data.hpp"

#include <algorithm>

namespace flexmbd {

int FeBodyData::nodeIndex(int id) const {
  const auto it = std::find(nodeIds.begin(), nodeIds.end(), id);
  return it == nodeIds.end() ? -1 : static_cast<int>(it - nodeIds.begin());
}

std::vector<int> FeBodyData::dofIndex() const {
  std::vector<int> idx(3 * nodeIds.size(), -1);
  for (int i = 0; i < numDofs(); ++i) {
    if (!dofs[i].isRotation()) idx[3 * dofs[i].node + dofs[i].direction] = i;
  }
  return idx;
}

std::vector<int> FeBodyData::rotationIndex() const {
  std::vector<int> idx(3 * nodeIds.size(), -1);
  for (int i = 0; i < numDofs(); ++i) {
    if (dofs[i].isRotation()) idx[3 * dofs[i].node + dofs[i].direction - 3] = i;
  }
  return idx;
}

bool FeBodyData::hasRotations() const {
  return std::any_of(dofs.begin(), dofs.end(), [](const FeDof& f) { return f.isRotation(); });
}

std::vector<int> FeBodyData::dofsOfNodes(const std::vector<int>& nodes) const {
  const std::vector<int> idx = dofIndex(), rot = rotationIndex();
  std::vector<int> rows;
  for (int a : nodes) {
    for (int k = 0; k < 3; ++k) rows.push_back(idx.at(3 * static_cast<size_t>(a) + k));
    for (int k = 0; k < 3; ++k) {
      if (rot.at(3 * static_cast<size_t>(a) + k) >= 0) rows.push_back(rot[3 * static_cast<size_t>(a) + k]);
    }
  }
  return rows;
}

}  // namespace flexmbd
