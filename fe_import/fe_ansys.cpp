#include "fe_import/fe_ansys.hpp"

#include <map>

#include "core/errors.hpp"
#include "fe_import/fe_text.hpp"

namespace flexmbd {

using namespace feread;

namespace {

/// A table with one header line (its first field not a number): the data lines' fields.
template <class Row>
void readTable(TextFile& f, const std::string& what, Row row) {
  std::string line;
  if (!f.next(line) || words(line).empty()) f.fail("expected a header line naming the columns of the " + what);
  bool any = false;
  while (f.next(line)) {
    const std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    row(w);
    any = true;
  }
  if (!any) throw InputError(f.path() + ": no " + what + " after the header line");
}

/// The MatrixMarket header "%%MatrixMarket matrix <format> <field> <symmetry>", comments,
/// and the size line: its fields.
std::vector<std::string> readMatrixMarketHeader(TextFile& f, const std::string& format, const std::string& field,
                                                std::string& symmetry) {
  std::string line;
  if (!f.next(line)) f.fail("the file is empty; expected a MatrixMarket header");
  const std::vector<std::string> h = words(line);
  if (h.size() != 5 || h[0] != "%%MatrixMarket" || h[1] != "matrix" || h[2] != format || h[3] != field ||
      (h[4] != "general" && h[4] != "symmetric")) {
    f.fail("the header is '" + trimmed(line) + "'; expected '%%MatrixMarket matrix " + format + " " + field +
           " general|symmetric'");
  }
  symmetry = h[4];
  while (f.next(line)) {
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '%') continue;
    return words(t);
  }
  f.fail("no size line after the header");
}

std::vector<int> readDofMap(const std::string& path, const FeBodyData& d, const std::map<int, int>& index) {
  TextFile f(path);
  std::string symmetry;
  const std::vector<std::string> size = readMatrixMarketHeader(f, "array", "integer", symmetry);
  if (size.size() != 2 || integerField(f, size[1], "the number of columns") != 1) {
    f.fail("the size line is not 'n 1'; expected the DOF mapping vector as one column");
  }
  const long n = integerField(f, size[0], "the number of rows");
  if (n != d.numNodes()) {
    f.fail("the DOF map has " + size[0] + " entries for the " + std::to_string(d.numNodes()) +
           " nodes of the coordinates; expected one per node");
  }
  std::vector<int> map;
  std::vector<int> firstLine(d.numNodes(), 0);
  std::string line;
  while (f.next(line)) {
    const std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    if (w.size() != 1) f.fail("the line has " + std::to_string(w.size()) + " fields; expected one node number");
    if (static_cast<long>(map.size()) == n) f.fail("more than the " + size[0] + " entries of the size line");
    const long id = integerField(f, w[0], "the node number");
    const auto found = index.find(static_cast<int>(id));
    if (found == index.end())
      f.fail("node " + w[0] + " is not in the nodal coordinates; expected the nodes of the mesh");
    const int a = found->second;
    if (firstLine[a] > 0) {
      f.fail("node " + w[0] + " is mapped twice (first on line " + std::to_string(firstLine[a]) +
             "); expected each node once");
    }
    firstLine[a] = f.lineNumber();
    map.push_back(a);
  }
  if (static_cast<long>(map.size()) != n) {
    f.fail("the DOF map ends after " + std::to_string(map.size()) + " of the " + size[0] + " entries of its size line");
  }
  return map;
}

SpMat readMatrixMarket(const std::string& path, int n) {
  TextFile f(path);
  std::string symmetry;
  const std::vector<std::string> size = readMatrixMarketHeader(f, "coordinate", "real", symmetry);
  if (size.size() != 3)
    f.fail("the size line has " + std::to_string(size.size()) + " fields; expected 'rows columns entries'");
  const long rows = integerField(f, size[0], "the number of rows"),
             cols = integerField(f, size[1], "the number of columns");
  const long nnz = integerField(f, size[2], "the number of entries");
  if (rows != n || cols != n) {
    f.fail("the matrix is " + size[0] + " x " + size[1] + "; expected " + std::to_string(n) + " x " +
           std::to_string(n) + " (3 DOF for each node of the DOF map)");
  }
  std::vector<MatrixEntry> entries;
  std::string line;
  while (f.next(line)) {
    const std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    if (w.size() != 3) f.fail("the line has " + std::to_string(w.size()) + " fields; expected 'row column value'");
    if (static_cast<long>(entries.size()) == nnz) f.fail("more than the " + size[2] + " entries of the size line");
    const long r = integerField(f, w[0], "the row"), c = integerField(f, w[1], "the column");
    entries.push_back(
        {static_cast<int>(r - 1), static_cast<int>(c - 1), realField(f, w[2], "the value"), f.lineNumber()});
  }
  if (static_cast<long>(entries.size()) != nnz) {
    f.fail("the file ends after " + std::to_string(entries.size()) + " of the " + size[2] +
           " entries of its size line");
  }
  return assembleSymmetric(entries, n, symmetry == "symmetric" ? SymmetricStorage::Lower : SymmetricStorage::Both,
                           path);
}

}  // namespace

FeBodyData readAnsysFe(const AnsysFeFiles& files) {
  FeBodyData d;
  d.source = files.coordinates;
  {
    TextFile f(files.coordinates);
    std::map<int, int> firstLine;
    readTable(f, "nodal coordinates", [&](const std::vector<std::string>& w) {
      if (w.size() != 4) f.fail("the line has " + std::to_string(w.size()) + " fields; expected 'node x y z'");
      const int id = static_cast<int>(integerField(f, w[0], "the node number"));
      if (!firstLine.emplace(id, f.lineNumber()).second) {
        f.fail("node " + w[0] + " is given twice (first on line " + std::to_string(firstLine[id]) +
               "); expected each node once");
      }
      Vec3 x;
      for (int k = 0; k < 3; ++k)
        x[k] = realField(f, w[k + 1], std::string("coordinate ") + "xyz"[k] + " of node " + w[0], true);
      d.nodeIds.push_back(id);
      d.coordinates.push_back(x);
    });
  }
  std::map<int, int> index;
  for (int a = 0; a < d.numNodes(); ++a) index[d.nodeIds[a]] = a;
  {
    static const std::map<std::string, int> counts = {{"Tet4", 4},     {"Tet10", 10},   {"Wedge6", 6},
                                                      {"Wedge15", 15}, {"Pyramid5", 5}, {"Pyramid13", 13},
                                                      {"Hex8", 8},     {"Hex20", 20}};
    TextFile f(files.elements);
    readTable(f, "elements", [&](const std::vector<std::string>& w) {
      if (w.size() < 2)
        f.fail("the line has " + std::to_string(w.size()) + " fields; expected 'element type nodes...'");
      const auto it = counts.find(w[1]);
      if (it == counts.end()) {
        f.fail("element type '" + w[1] +
               "'; expected Tet4, Tet10, Wedge6, Wedge15, Pyramid5, Pyramid13, Hex8 or Hex20");
      }
      if (static_cast<int>(w.size()) != it->second + 2) {
        f.fail("element " + w[0] + " has " + std::to_string(w.size() - 2) + " nodes; expected " +
               std::to_string(it->second) + " for " + w[1]);
      }
      FeElement e;
      e.id = static_cast<int>(integerField(f, w[0], "the element number"));
      e.type = w[1];
      for (size_t i = 2; i < w.size(); ++i) {
        const auto a = index.find(static_cast<int>(integerField(f, w[i], "a node of element " + w[0])));
        if (a == index.end())
          f.fail("element " + w[0] + " names node " + w[i] + ", which the nodal coordinates do not give");
        e.nodes.push_back(a->second);
      }
      d.elements.push_back(std::move(e));
    });
  }
  for (const int a : readDofMap(files.dofMap, d, index)) {
    for (int k = 0; k < 3; ++k) d.dofs.push_back({a, k});
  }
  d.mass = readMatrixMarket(files.mass, d.numDofs());
  d.stiffness = readMatrixMarket(files.stiffness, d.numDofs());
  checkBodyData(d, files.mass, files.stiffness);
  return d;
}

}  // namespace flexmbd
