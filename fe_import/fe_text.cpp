#include "fe_import/fe_text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <utility>

#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {

namespace feread {

TextFile::TextFile(std::string path) : path_(std::move(path)), in_(path_) {
  if (!in_) throw InputError(path_ + ": cannot open the file for reading");
}

bool TextFile::next(std::string& line) {
  if (!std::getline(in_, line)) return false;
  ++line_;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

void TextFile::fail(const std::string& what) const { failAt(line_, what); }

void TextFile::failAt(int line, const std::string& what) const {
  throw InputError(path_ + ", line " + std::to_string(line) + ": " + what);
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> splitFields(const std::string& line, const std::string& separators) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t p = line.find_first_of(separators, start);
    out.push_back(trimmed(line.substr(start, p == std::string::npos ? std::string::npos : p - start)));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  if (out.size() > 1 && out.back().empty()) out.pop_back();  // after a trailing separator
  return out;
}

double realField(const TextFile& f, const std::string& field, const std::string& what, bool decimalComma) {
  std::string s = field;
  if (decimalComma && s.find('.') == std::string::npos) std::replace(s.begin(), s.end(), ',', '.');
  const char* b = s.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(b, &end);
  if (s.empty() || end != b + s.size() || errno == ERANGE || !std::isfinite(v)) {
    f.fail(what + " is '" + field + "'; expected a finite real number");
  }
  return v;
}

long integerField(const TextFile& f, const std::string& field, const std::string& what) {
  const char* b = field.c_str();
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(b, &end, 10);
  if (field.empty() || end != b + field.size() || errno == ERANGE) {
    f.fail(what + " is '" + field + "'; expected an integer");
  }
  return v;
}

SpMat assembleSymmetric(const std::vector<MatrixEntry>& entries, int n, SymmetricStorage storage,
                        const std::string& path) {
  const auto where = [&](int line) { return path + ", line " + std::to_string(line) + ": "; };
  const auto pos = [](int r, int c) { return "(" + std::to_string(r + 1) + ", " + std::to_string(c + 1) + ")"; };
  std::map<std::pair<int, int>, const MatrixEntry*> stored;
  double largest = 0.0;
  for (const MatrixEntry& e : entries) {
    if (e.row < 0 || e.col < 0 || e.row >= n || e.col >= n) {
      throw InputError(where(e.line) + "entry " + pos(e.row, e.col) + " is outside the " + std::to_string(n) + " x " +
                       std::to_string(n) + " matrix; expected row and column from 1 to " + std::to_string(n));
    }
    if (storage == SymmetricStorage::Lower && e.row < e.col) {
      throw InputError(where(e.line) + "entry " + pos(e.row, e.col) +
                       " is above the diagonal; expected the lower triangle only (row >= column) of a "
                       "MatrixMarket symmetric matrix");
    }
    if (storage == SymmetricStorage::Upper && e.row > e.col) {
      throw InputError(where(e.line) + "entry " + pos(e.row, e.col) +
                       " is below the diagonal; expected the upper triangle only (row <= column), as CalculiX "
                       "stores a symmetric matrix");
    }
    const auto ins = stored.emplace(std::make_pair(e.row, e.col), &e);
    if (!ins.second) {
      throw InputError(where(e.line) + "entry " + pos(e.row, e.col) + " is given twice (first on line " +
                       std::to_string(ins.first->second->line) + "); expected each entry once");
    }
    largest = std::max(largest, std::abs(e.value));
  }
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(2 * entries.size());
  for (const MatrixEntry& e : entries) {
    t.emplace_back(e.row, e.col, e.value);
    if (storage != SymmetricStorage::Both) {
      if (e.row != e.col) t.emplace_back(e.col, e.row, e.value);
      continue;
    }
    const auto partner = stored.find(std::make_pair(e.col, e.row));
    const double other = partner == stored.end() ? 0.0 : partner->second->value;
    if (std::abs(e.value - other) > kSymmetryTolerance * largest) {
      throw InputError(where(e.line) + "entry " + pos(e.row, e.col) + " = " + fmt(e.value) + " but entry " +
                       pos(e.col, e.row) + " = " + fmt(other) + (partner == stored.end() ? " (not given)" : "") +
                       "; expected a symmetric matrix with both triangles stored (to " + fmt(kSymmetryTolerance) +
                       " of the largest entry, " + fmt(largest) + ")");
    }
  }
  SpMat A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  for (const std::string& s : splitFields(line, " \t")) {
    if (!s.empty()) out.push_back(s);
  }
  return out;
}

std::vector<std::string> matrixFields(const std::string& line) {
  std::vector<std::string> out;
  for (const std::string& s : splitFields(line, " \t,")) {
    if (!s.empty()) out.push_back(s);
  }
  return out;
}

std::map<long, int> labelIndex(const FeBodyData& d) {
  std::map<long, int> index;
  for (int a = 0; a < d.numNodes(); ++a) index[d.nodeIds[a]] = a;
  return index;
}

SpMat readRowColumnMatrix(const std::string& path, int n, SymmetricStorage storage, const std::string& dofWhat) {
  TextFile f(path);
  std::vector<MatrixEntry> entries;
  std::string line;
  while (f.next(line)) {
    const std::string t = trimmed(line);
    if (t.empty()) continue;
    const std::vector<std::string> fields = matrixFields(t);
    if (fields.size() != 3)
      f.fail("the line has " + std::to_string(fields.size()) + " fields; expected 'row column value'");
    const long r = integerField(f, fields[0], "the row"), c = integerField(f, fields[1], "the column");
    if (r < 1 || c < 1 || r > n || c > n) {
      f.fail("entry (" + fields[0] + ", " + fields[1] + ") is outside the " + std::to_string(n) + " DOF " + dofWhat +
             "; expected row and column from 1 to " + std::to_string(n));
    }
    entries.push_back(
        {static_cast<int>(r - 1), static_cast<int>(c - 1), realField(f, fields[2], "the value"), f.lineNumber()});
  }
  if (entries.empty()) throw InputError(path + ": no matrix entries; expected lines 'row column value'");
  return assembleSymmetric(entries, n, storage, path);
}

std::string dofName(const FeDof& f) {
  static const char* const names[] = {"x", "y", "z", "rotation x", "rotation y", "rotation z"};
  return f.direction >= 0 && f.direction < 6 ? names[f.direction] : "?";
}

void checkBodyData(const FeBodyData& d, const std::string& massPath, const std::string& stiffnessPath) {
  const int nn = d.numNodes(), nd = d.numDofs();
  const std::string dofText = std::to_string(nd);
  std::vector<int> seen(6 * nn, -1);
  for (int i = 0; i < nd; ++i) {
    const FeDof& f = d.dofs[i];
    if (f.node < 0 || f.node >= nn || f.direction < 0 || f.direction > 5 || seen[6 * f.node + f.direction] >= 0) {
      throw InputError(stiffnessPath + ": the DOF map gives row " + std::to_string(i + 1) +
                       " to a node and direction already mapped or unknown; expected each node's x, y, z (and "
                       "rotations, if any) once");
    }
    seen[6 * f.node + f.direction] = i;
  }
  for (int a = 0; a < nn; ++a) {
    const int translations = (seen[6 * a] >= 0) + (seen[6 * a + 1] >= 0) + (seen[6 * a + 2] >= 0);
    const int rotations = (seen[6 * a + 3] >= 0) + (seen[6 * a + 4] >= 0) + (seen[6 * a + 5] >= 0);
    if (translations != 3 || (rotations != 0 && rotations != 3)) {
      throw InputError(stiffnessPath + ": node " + std::to_string(d.nodeIds[a]) + " has " +
                       std::to_string(translations) + " translations and " + std::to_string(rotations) +
                       " rotations in the matrices; expected x, y, z (3 DOF: solids) or x, y, z and the three "
                       "rotations (6 DOF: beams, shells)");
    }
  }
  const auto sizeOk = [&](const SpMat& A) { return A.rows() == nd && A.cols() == nd; };
  if (!sizeOk(d.mass)) throw InputError(massPath + ": the mass matrix is not " + dofText + " x " + dofText);
  if (!sizeOk(d.stiffness))
    throw InputError(stiffnessPath + ": the stiffness matrix is not " + dofText + " x " + dofText);
  const VecX kdiag = d.stiffness.diagonal();
  for (int i = 0; i < nd; ++i) {
    if (!(kdiag[i] > 0.0)) {
      const FeDof& f = d.dofs[i];
      throw InputError(stiffnessPath + ": row " + std::to_string(i + 1) + " (node " +
                       std::to_string(d.nodeIds[f.node]) + ", direction " + dofName(f) +
                       ") has the stiffness diagonal " + fmt(kdiag[i]) +
                       "; expected a positive value (a node outside every element, or matrices of another mesh?)");
    }
  }
  for (int k = 0; k < 3; ++k) {
    VecX r = VecX::Zero(nd);
    for (int i = 0; i < nd; ++i) r[i] = d.dofs[i].direction == k ? 1.0 : 0.0;
    const double m = r.dot(d.mass * r);
    if (!(m > 0.0)) {
      throw InputError(massPath + ": the total mass in direction " + "xyz"[k] +
                       " (r^T M r, r the rigid translation) is " + fmt(m) + "; expected a positive mass");
    }
  }
}

}  // namespace feread
}  // namespace flexmbd
