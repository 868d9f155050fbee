#include "fe_import/fe_abaqus.hpp"

#include <algorithm>
#include <map>

#include "core/errors.hpp"
#include "fe_import/fe_inp.hpp"
#include "fe_import/fe_text.hpp"

namespace flexmbd {

using namespace feread;

namespace {

/// The number of fields of the first data line of `path` (3: FORMAT=COORDINATE, 5:
/// FORMAT=MATRIX INPUT), or 0 for a file without data lines.
int fieldsOfFirstLine(const std::string& path) {
  TextFile f(path);
  std::string line;
  while (f.next(line)) {
    const std::string t = trimmed(line);
    if (t.empty() || t.rfind("**", 0) == 0) continue;
    return static_cast<int>(matrixFields(t).size());
  }
  return 0;
}

/// True for the element types whose nodes carry rotations (beams, shells, ROTARYI).
bool hasRotationalDofs(const std::string& type) {
  const char c = type.empty() ? ' ' : static_cast<char>(std::toupper(static_cast<unsigned char>(type[0])));
  return c == 'B' || c == 'S' || c == 'R';
}

/// One entry of a FORMAT=MATRIX INPUT file: "row node, row DOF, column node, column DOF,
/// value" (DOF 1, 2, 3 translations, 4, 5, 6 rotations).
struct NodeDofEntry {
  int rowNode, rowDir, colNode, colDir;
  double value;
  int line;
};

/// The entries of `path` with their nodes as indices into `d`'s nodes.
/// @throws InputError naming the file and line: not 5 fields, an unknown node, a DOF
/// outside 1 to 6, a value that is not a finite real, no entries.
std::vector<NodeDofEntry> readNodeDofEntries(const std::string& path, const FeBodyData& d,
                                             const std::map<long, int>& index) {
  TextFile f(path);
  std::vector<NodeDofEntry> out;
  std::string line;
  const auto node = [&](const std::string& s, const char* what) {
    const long label = integerField(f, s, what);
    const auto it = index.find(label);
    if (it == index.end()) f.fail(std::string(what) + " " + s + " is not a node of " + d.source);
    return it->second;
  };
  const auto dof = [&](const std::string& s, const char* what) {
    const long k = integerField(f, s, what);
    if (k < 1 || k > 6) {
      f.fail(std::string(what) + " is " + s + "; expected 1, 2, 3 (translations) or 4, 5, 6 (rotations)");
    }
    return static_cast<int>(k - 1);
  };
  while (f.next(line)) {
    const std::string t = trimmed(line);
    if (t.empty() || t.rfind("**", 0) == 0) continue;
    const std::vector<std::string> w = matrixFields(t);
    if (w.size() != 5) {
      f.fail("the line has " + std::to_string(w.size()) +
             " fields; expected 'row node, row DOF, column node, column DOF, value' (FORMAT=MATRIX INPUT) like "
             "the lines before");
    }
    NodeDofEntry e{node(w[0], "the row node"), dof(w[1], "the row DOF"), node(w[2], "the column node"),
                   dof(w[3], "the column DOF"), realField(f, w[4], "the value"), f.lineNumber()};
    out.push_back(e);
  }
  if (out.empty()) throw InputError(path + ": no matrix entries; expected lines 'node, DOF, node, DOF, value'");
  return out;
}

/// The matrix of node-DOF entries in the DOF order `row` (row[6 a + k]: the matrix row of
/// node a's direction k), both triangles (one triangle stored: mirrored; both: checked).
SpMat assembleNodeDof(const std::vector<NodeDofEntry>& in, const std::vector<int>& row, int n,
                      const std::string& path) {
  std::vector<MatrixEntry> entries;
  bool below = false, above = false;
  for (const NodeDofEntry& e : in) {
    const MatrixEntry m{row[6 * e.rowNode + e.rowDir], row[6 * e.colNode + e.colDir], e.value, e.line};
    below = below || m.row > m.col;
    above = above || m.row < m.col;
    entries.push_back(m);
  }
  const SymmetricStorage storage =
      below && above ? SymmetricStorage::Both : (above ? SymmetricStorage::Upper : SymmetricStorage::Lower);
  return assembleSymmetric(entries, n, storage, path);
}

/// FORMAT=MATRIX INPUT: the DOF are those the two files name, node by node in ascending
/// label order, each node's directions in order.
void readMatrixInput(FeBodyData& d, const std::string& massPath, const std::string& stiffnessPath) {
  const std::map<long, int> index = labelIndex(d);
  const std::vector<NodeDofEntry> m = readNodeDofEntries(massPath, d, index);
  const std::vector<NodeDofEntry> k = readNodeDofEntries(stiffnessPath, d, index);
  std::vector<int> row(6 * static_cast<size_t>(d.numNodes()), -1);
  for (const auto* list : {&m, &k}) {
    for (const NodeDofEntry& e : *list) {
      row[6 * e.rowNode + e.rowDir] = 0;
      row[6 * e.colNode + e.colDir] = 0;
    }
  }
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (row[i] < 0) continue;
    row[i] = d.numDofs();
    d.dofs.push_back({static_cast<int>(i / 6), static_cast<int>(i % 6)});
  }
  d.mass = assembleNodeDof(m, row, d.numDofs(), massPath);
  d.stiffness = assembleNodeDof(k, row, d.numDofs(), stiffnessPath);
}

/// FORMAT=COORDINATE: 3 DOF per node (solids) or 6 (beams, shells), over the nodes in
/// ascending label order.
void readCoordinate(FeBodyData& d, const std::string& inpPath, const std::string& massPath,
                    const std::string& stiffnessPath) {
  int structural = 0;
  for (const FeElement& e : d.elements) structural += hasRotationalDofs(e.type);
  if (structural > 0 && structural < static_cast<int>(d.elements.size())) {
    throw InputError(massPath + ": the matrices are in FORMAT=COORDINATE (global DOF numbers) but " + inpPath +
                     " mixes solids (3 DOF per node) with beams or shells (6); expected FORMAT=MATRIX INPUT "
                     "(lines 'node, DOF, node, DOF, value'), which names each node's DOF");
  }
  const int perNode = structural > 0 ? 6 : 3;
  for (int a = 0; a < d.numNodes(); ++a) {
    for (int k = 0; k < perNode; ++k) d.dofs.push_back({a, k});
  }
  const std::string dofWhat = "of the nodes (" + std::to_string(perNode) + " per node)";
  d.mass = readRowColumnMatrix(massPath, d.numDofs(), SymmetricStorage::Both, dofWhat);
  d.stiffness = readRowColumnMatrix(stiffnessPath, d.numDofs(), SymmetricStorage::Both, dofWhat);
}

}  // namespace

SpMat readAbaqusPreloadedStiffness(const std::string& path, const FeBodyData& body, std::vector<int>& held) {
  if (fieldsOfFirstLine(path) != 5) {
    throw InputError(path + ": the preloaded stiffness is not in FORMAT=MATRIX INPUT; expected lines 'node, DOF, "
                     "node, DOF, value', which name the DOF the preload run kept");
  }
  const std::map<long, int> index = labelIndex(body);
  const std::vector<NodeDofEntry> entries = readNodeDofEntries(path, body, index);
  std::vector<int> row(6 * static_cast<size_t>(body.numNodes()), -1);
  for (int i = 0; i < body.numDofs(); ++i) row[6 * body.dofs[i].node + body.dofs[i].direction] = i;
  std::vector<char> present(body.numDofs(), 0);
  for (const NodeDofEntry& e : entries) {
    for (const auto& [node, dir] : {std::make_pair(e.rowNode, e.rowDir), std::make_pair(e.colNode, e.colDir)}) {
      if (row[6 * node + dir] < 0) {
        throw InputError(path + ", line " + std::to_string(e.line) + ": node " + std::to_string(body.nodeIds[node]) +
                         ", DOF " + std::to_string(dir + 1) + " is not a DOF of " + body.source +
                         "; expected the body's own mesh and DOF");
      }
      present[row[6 * node + dir]] = 1;
    }
  }
  held.clear();
  for (int i = 0; i < body.numDofs(); ++i) {
    if (!present[i]) held.push_back(i);
  }
  return assembleNodeDof(entries, row, body.numDofs(), path);
}

FeBodyData readAbaqusFe(const std::string& inpPath, const std::string& massPath, const std::string& stiffnessPath) {
  FeBodyData d = readInpMesh(inpPath, InpElements::SolidsBeamsShells);
  const int fm = fieldsOfFirstLine(massPath), fk = fieldsOfFirstLine(stiffnessPath);
  if (fm == 5 && fk == 5) {
    readMatrixInput(d, massPath, stiffnessPath);
  } else if (fm == 5 || fk == 5) {
    throw InputError((fm == 5 ? stiffnessPath : massPath) +
                     ": its lines are not in the format of the other matrix file (FORMAT=MATRIX INPUT, 'node, DOF, "
                     "node, DOF, value'); expected both matrices in one format");
  } else {
    readCoordinate(d, inpPath, massPath, stiffnessPath);
  }
  checkBodyData(d, massPath, stiffnessPath);
  return d;
}

}  // namespace flexmbd
