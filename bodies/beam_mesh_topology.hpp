// The topology checks every beam mesh (planar and spatial) passes before its elements
// are built: node indices in range, no element with both ends at one node, every node
// used, the mesh connected.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace flexmbd {

/// @param elementNodes the two node indices of each element.
/// @throws InputError naming `owner`, the element or node and what is wrong.
void checkBeamMeshTopology(int numNodes, const std::vector<std::pair<int, int>>& elementNodes,
                           const std::string& owner);

}  // namespace flexmbd
