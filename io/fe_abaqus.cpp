#include "io/fe_abaqus.hpp"

#include "io/fe_inp.hpp"
#include "io/fe_text.hpp"

namespace flexmbd {

using namespace feread;

FeBodyData readAbaqusFe(const std::string& inpPath, const std::string& massPath, const std::string& stiffnessPath) {
  FeBodyData d = readInpMesh(inpPath);
  // the DOF numbers of the matrices: 3 per node, x y z, ascending labels
  for (int a = 0; a < d.numNodes(); ++a) {
    for (int k = 0; k < 3; ++k) d.dofs.push_back({a, k});
  }
  const std::string dofWhat = "of the nodes (3 per node)";
  d.mass = readRowColumnMatrix(massPath, d.numDofs(), SymmetricStorage::Both, dofWhat);
  d.stiffness = readRowColumnMatrix(stiffnessPath, d.numDofs(), SymmetricStorage::Both, dofWhat);
  checkBodyData(d, massPath, stiffnessPath);
  return d;
}

}  // namespace flexmbd
