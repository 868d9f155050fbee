#include "bodies/beam_mesh_topology.hpp"

#include <numeric>

#include "core/errors.hpp"

namespace flexmbd {

void checkBeamMeshTopology(int nn, const std::vector<std::pair<int, int>>& elementNodes, const std::string& owner) {
  if (elementNodes.empty()) throw InputError(owner + ": the beam mesh has no elements");
  // every node used, the mesh connected (union-find)
  std::vector<int> parent(nn);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<bool> used(nn, false);
  for (size_t e = 0; e < elementNodes.size(); ++e) {
    const auto [a, b] = elementNodes[e];
    const std::string who = owner + ": element " + std::to_string(e);
    for (int n : {a, b}) {
      if (n < 0 || n >= nn) {
        throw InputError(who + ": node " + std::to_string(n) + " does not exist (nodes 0.." + std::to_string(nn - 1) +
                         ")");
      }
      used[n] = true;
    }
    if (a == b) throw InputError(who + ": both ends are node " + std::to_string(a));
    parent[find(a)] = find(b);
  }
  for (int n = 0; n < nn; ++n) {
    if (!used[n]) throw InputError(owner + ": node " + std::to_string(n) + " belongs to no element");
    if (find(n) != find(0)) {
      throw InputError(owner + ": the mesh is not connected (node " + std::to_string(n) + " is cut off from node 0)");
    }
  }
}

}  // namespace flexmbd
