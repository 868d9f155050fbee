/// @file
/// The topology checks every beam mesh (planar and spatial) passes before its elements
/// are built: node indices in range, no element with both ends at one node, every node
/// used, the mesh connected.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace flexmbd {

/// @param numNodes the number of nodes of the mesh (node indices are 0 .. numNodes - 1).
/// @param elementNodes the two node indices of each element.
/// @param owner the body or mesh the messages name.
/// @throws InputError naming `owner`, the element or node and what is wrong.
void checkBeamMeshTopology(int numNodes, const std::vector<std::pair<int, int>>& elementNodes,
                           const std::string& owner);

}  // namespace flexmbd
