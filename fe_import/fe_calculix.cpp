#include "fe_import/fe_calculix.hpp"

#include <array>

#include <map>
#include <set>
#include <utility>

#include "core/errors.hpp"
#include "fe_import/fe_inp.hpp"
#include "fe_import/fe_text.hpp"

namespace flexmbd {

using namespace feread;

CalculixFeFiles CalculixFeFiles::ofJob(const std::string& jobname) {
  return {jobname + ".inp", jobname + ".sti", jobname + ".mas", jobname + ".dof"};
}

namespace {

/// The .dof file: equation i (line i) moves node `node` (index into d.nodeIds) in
/// direction `direction` (0, 1, 2), written "label.direction" with direction 1, 2, 3.
std::vector<FeDof> readDofFile(const std::string& path, const FeBodyData& d, const std::string& inpPath,
                               bool requireAll = true) {
  TextFile f(path);
  std::map<long, int> index;
  for (int a = 0; a < d.numNodes(); ++a) index[d.nodeIds[a]] = a;
  std::vector<FeDof> dofs;
  std::map<std::pair<int, int>, int> lineOf;  // (node, direction) -> its line
  std::string line;
  while (f.next(line)) {
    const std::string t = trimmed(line);
    const auto dot = t.find('.');
    if (t.empty() || dot == std::string::npos || t.find('.', dot + 1) != std::string::npos) {
      f.fail("the line is '" + t + "'; expected 'node.direction' (e.g. 12.3: node 12, z), one per equation");
    }
    const long label = integerField(f, t.substr(0, dot), "the node");
    const long dir = integerField(f, t.substr(dot + 1), "the direction");
    if (dir < 1 || dir > 3) {
      f.fail("node " + std::to_string(label) + " has direction " + std::to_string(dir) +
             "; expected 1, 2 or 3 (the translations of solid elements)");
    }
    const auto it = index.find(label);
    if (it == index.end()) f.fail("node " + std::to_string(label) + " is not defined in " + inpPath);
    const FeDof dof{it->second, static_cast<int>(dir - 1)};
    const auto ins = lineOf.emplace(std::make_pair(dof.node, dof.direction), f.lineNumber());
    if (!ins.second) {
      f.fail("node " + std::to_string(label) + " direction " + std::to_string(dir) + " is given twice (first on line " +
             std::to_string(ins.first->second) + "); expected each node and direction once");
    }
    dofs.push_back(dof);
  }
  for (int a = 0; a < d.numNodes() && requireAll; ++a) {
    for (int k = 0; k < 3; ++k) {
      if (!lineOf.count({a, k})) {
        throw InputError(path + ": node " + std::to_string(d.nodeIds[a]) + " direction " + std::to_string(k + 1) +
                         " has no equation (" + std::to_string(dofs.size()) + " lines for " +
                         std::to_string(d.numNodes()) +
                         " nodes); expected the free matrices, every node's three directions (no *BOUNDARY in the "
                         "exporting deck, every node in an element)");
      }
    }
  }
  return dofs;
}

}  // namespace

FeBodyData readCalculixFe(const CalculixFeFiles& files) {
  FeBodyData d = readInpMesh(files.inp, InpElements::Solids);
  d.dofs = readDofFile(files.dofs, d, files.inp);
  const std::string dofWhat = "of " + files.dofs;
  d.stiffness = readRowColumnMatrix(files.stiffness, d.numDofs(), SymmetricStorage::Upper, dofWhat);
  d.mass = readRowColumnMatrix(files.mass, d.numDofs(), SymmetricStorage::Upper, dofWhat);
  checkBodyData(d, files.mass, files.stiffness);
  return d;
}

SpMat readCalculixPreloadedStiffness(const CalculixFeFiles& files, const FeBodyData& body, std::vector<int>& held) {
  const FeBodyData mesh = readInpMesh(files.inp, InpElements::Solids);
  if (mesh.nodeIds != body.nodeIds) {
    throw InputError(files.inp + ": its nodes are not those of " + body.source +
                     "; expected the deck of the body with the preload steps added");
  }
  for (int a = 0; a < body.numNodes(); ++a) {
    if ((mesh.coordinates[a] - body.coordinates[a]).norm() > 1e-9 * (1.0 + body.coordinates[a].norm())) {
      throw InputError(files.inp + ": node " + std::to_string(body.nodeIds[a]) + " is not where " + body.source +
                       " has it; expected the same mesh");
    }
  }
  const std::vector<FeDof> dofs = readDofFile(files.dofs, body, files.inp, false);
  const SpMat K = readRowColumnMatrix(files.stiffness, static_cast<int>(dofs.size()), SymmetricStorage::Upper,
                                      "of " + files.dofs);
  if (body.hasRotations()) {
    throw InputError(files.stiffness + ": a CalculiX preloaded stiffness for " + body.source +
                     ", whose nodes have rotations; expected a solid body (CalculiX exports 3 DOF per node)");
  }
  // equation i of the export -> the body's DOF index
  std::vector<int> bodyIndex(body.numNodes() * 3, -1);
  for (int i = 0; i < body.numDofs(); ++i) bodyIndex[3 * body.dofs[i].node + body.dofs[i].direction] = i;
  std::vector<int> map(dofs.size());
  std::vector<char> present(body.numDofs(), 0);
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    map[i] = bodyIndex[3 * dofs[i].node + dofs[i].direction];
    present[map[i]] = 1;
  }
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < K.outerSize(); ++j) {
    for (SpMat::InnerIterator it(K, j); it; ++it) t.emplace_back(map[it.row()], map[j], it.value());
  }
  SpMat out(body.numDofs(), body.numDofs());
  out.setFromTriplets(t.begin(), t.end());
  held.clear();
  for (int i = 0; i < body.numDofs(); ++i) {
    if (!present[i]) held.push_back(i);
  }
  return out;
}

// ----- .frd ------------------------------------------------------------------------------

namespace {

/// Columns [start, start + width) of `line`, trimmed ("" past its end).
std::string column(const std::string& line, size_t start, size_t width) {
  return start >= line.size() ? std::string() : trimmed(line.substr(start, width));
}

class FrdReader {
 public:
  explicit FrdReader(const std::string& path) : f_(path) {}

  FrdResults read() {
    std::string line;
    int pendingMode = 0;
    while (f_.next(line)) {
      const std::string t = trimmed(line);
      if (t.empty()) continue;
      if (t == "9999") {
        ended_ = true;
        continue;
      }
      if (ended_) f_.fail("a line after '9999'; expected the end of the file");
      if (t.rfind("1C", 0) == 0 || t.rfind("1U", 0) == 0) continue;  // the header and its user lines
      if (t.rfind("1P", 0) == 0) {  // a parameter line: "1PMODE  3" numbers the next mode
        const std::vector<std::string> w = words(t);
        if (w[0] == "1PMODE") {
          if (w.size() != 2) f_.fail("the line '" + t + "' has no single mode number; expected '1PMODE <n>'");
          pendingMode = static_cast<int>(integerField(f_, w[1], "the mode number"));
        }
        continue;
      }
      if (t.rfind("2C", 0) == 0) {
        readNodeBlock(t);
      } else if (t.rfind("3C", 0) == 0) {
        skipElementBlock();
      } else if (t.rfind("100C", 0) == 0) {
        readResultBlock(line, pendingMode);
        pendingMode = 0;
      } else {
        f_.fail("the line '" + t.substr(0, 20) +
                "' starts no block; expected a header line (1C, 1U, 1P), a node (2C), element (3C) or result "
                "(100C) block, or 9999 (the end). An ASCII .frd file as ccx writes it?");
      }
    }
    if (!ended_) {
      throw InputError(f_.path() + ": the file ends after line " + std::to_string(f_.lineNumber()) +
                       " without '9999'; expected a finished run's .frd file");
    }
    return std::move(r_);
  }

 private:
  /// The data line's leading key (" -1", " -2", " -3"): its trimmed first 3 columns.
  static std::string key(const std::string& line) { return column(line, 0, 3); }

  /// Format indicator: 0 short (I5 node numbers), 1 long (I10); 2 binary is refused.
  int nodeWidth(long format) const {
    if (format == 0) return 5;
    if (format == 1) return 10;
    f_.fail("format " + std::to_string(format) + " (2: binary); expected the ASCII formats 0 (short) or 1 (long)");
  }

  /// The next line of a block: @throws at the end of the file (block not closed).
  std::string blockLine(const std::string& what) {
    std::string line;
    if (!f_.next(line)) {
      throw InputError(f_.path() + ": the file ends inside the " + what + " after line " +
                       std::to_string(f_.lineNumber()) + "; expected ' -3' closing it");
    }
    return line;
  }

  /// "    2C   <count>   <format>", then " -1 node x y z" lines, " -3".
  void readNodeBlock(const std::string& header) {
    const std::vector<std::string> w = words(header);
    if (w.size() != 3)
      f_.fail("the node block header has " + std::to_string(w.size()) + " fields; expected '2C <count> <format>'");
    const long count = integerField(f_, w[1], "the node count");
    const int width = nodeWidth(integerField(f_, w[2], "the format"));
    const int headerLine = f_.lineNumber();
    while (true) {
      const std::string line = blockLine("node block");
      if (key(line) == "-3") break;
      if (key(line) != "-1") f_.fail("expected a node line ' -1 <node> <x> <y> <z>' or ' -3' in the node block");
      const long node = integerField(f_, column(line, 3, width), "the node number");
      Vec3 x;
      for (int k = 0; k < 3; ++k) {
        x[k] = realField(f_, column(line, 3 + width + 12 * k, 12), std::string("coordinate ") + "xyz"[k]);
      }
      if (!r_.nodes.emplace(static_cast<int>(node), x).second) {
        f_.fail("node " + std::to_string(node) + " is given twice in the node block; expected each node once");
      }
    }
    if (static_cast<long>(r_.nodes.size()) != count) {
      f_.failAt(headerLine, "the node block header announces " + std::to_string(count) + " nodes, the block has " +
                                std::to_string(r_.nodes.size()) + "; expected the same");
    }
  }

  void skipElementBlock() {
    while (true) {
      const std::string line = blockLine("element block");
      const std::string k = key(line);
      if (k == "-3") return;
      if (k != "-1" && k != "-2") f_.fail("expected an element line (' -1', ' -2') or ' -3' in the element block");
    }
  }

  /// "  100C<set><value><count><text><type><step><analysis><format>", " -4 NAME ncomp irtype",
  /// ncomp " -5" component lines, data lines, " -3".
  void readResultBlock(const std::string& header, int mode) {
    const int headerLine = f_.lineNumber();
    if (header.size() < 75) {
      f_.fail("the result block header has " + std::to_string(header.size()) +
              " columns; expected at least 75 (the fixed columns of '  100C': set, value, node count, text, type, "
              "step, analysis, format)");
    }
    const double value = realField(f_, column(header, 12, 12), "the step value (columns 13-24)");
    const long count = integerField(f_, column(header, 24, 12), "the node count (columns 25-36)");
    const long type = integerField(f_, column(header, 56, 2), "the analysis type (columns 57-58)");
    const long number = integerField(f_, column(header, 58, 5), "the step number (columns 59-63)");
    const std::string analysis = column(header, 63, 10);
    const int width = nodeWidth(integerField(f_, column(header, 73, 2), "the format (columns 74-75)"));

    std::string line = blockLine("result block");
    std::vector<std::string> w = words(line);
    if (w.size() < 3 || w[0] != "-4") f_.fail("expected ' -4  <name>  <components>  <type>' after the '100C' line");
    FrdBlock b;
    b.name = w[1];
    const long declared = integerField(f_, w[2], "the component count");
    long listed = 0;
    while (true) {
      line = blockLine("result block " + b.name);
      if (key(line) != "-5") break;
      ++listed;
      const std::string name = column(line, 5, 8);
      const std::string exist = column(line, 33, 5);
      // IEXIST 1: computed by the viewer from the others (DISP's ALL), no value in the lines
      if (!(!exist.empty() && integerField(f_, exist, "IEXIST (columns 34-38)") == 1)) b.components.push_back(name);
    }
    if (listed != declared || b.components.empty()) {
      f_.fail("block " + b.name + " declares " + std::to_string(declared) + " components and lists " +
              std::to_string(listed) + " (' -5' lines), " + std::to_string(b.components.size()) +
              " of them stored; expected as many as declared, at least one stored");
    }
    const size_t nc = b.components.size();
    while (key(line) != "-3") {
      if (key(line) != "-1") f_.fail("expected a data line ' -1 <node> <values>' or ' -3' in block " + b.name);
      const long node = integerField(f_, column(line, 3, width), "the node number");
      if (!r_.nodes.empty() && !r_.nodes.count(static_cast<int>(node))) {
        f_.fail("block " + b.name + " gives node " + std::to_string(node) + ", which the node block (2C) lacks");
      }
      std::vector<double> v;
      size_t start = 3 + width;
      while (true) {
        for (size_t k = 0; k < 6 && v.size() < nc; ++k, start += 12) {
          const std::string field = column(line, start, 12);
          if (field.empty()) {
            f_.fail("node " + std::to_string(node) + " of block " + b.name + " has " + std::to_string(v.size()) +
                    " values; expected " + std::to_string(nc) + " (" + b.components.front() + " ... " +
                    b.components.back() + "), 12 columns each");
          }
          v.push_back(realField(f_, field,
                                b.name + " component " + b.components[v.size()] + " of node " + std::to_string(node)));
        }
        if (v.size() == nc) break;
        line = blockLine("result block " + b.name);  // a continuation line " -2" (more than 6 values)
        if (key(line) != "-2") f_.fail("expected a continuation line ' -2' of node " + std::to_string(node));
        start = 3 + width;
      }
      if (column(line, start, std::string::npos) != "") {
        f_.fail("node " + std::to_string(node) + " of block " + b.name + " has more than the " + std::to_string(nc) +
                " values expected");
      }
      if (!b.values.emplace(static_cast<int>(node), std::move(v)).second) {
        f_.fail("node " + std::to_string(node) + " is given twice in block " + b.name + "; expected each node once");
      }
      line = blockLine("result block " + b.name);
    }
    if (static_cast<long>(b.values.size()) != count) {
      f_.failAt(headerLine, "the header of block " + b.name + " announces " + std::to_string(count) +
                                " nodes, the block has " + std::to_string(b.values.size()) + "; expected the same");
    }
    // blocks of one step share its header's step number (ccx: DISP, STRESS, ... of a mode)
    if (r_.steps.empty() || r_.steps.back().number != number || r_.steps.back().type != type) {
      FrdStep s;
      s.number = static_cast<int>(number);
      s.type = static_cast<int>(type);
      s.analysis = analysis;
      s.value = value;
      s.mode = mode;
      r_.steps.push_back(std::move(s));
    }
    FrdStep& s = r_.steps.back();
    if (s.blocks.count(b.name)) {
      f_.failAt(headerLine, "block " + b.name + " is given twice for step " + std::to_string(number) +
                                "; expected each block once per step");
    }
    const std::string name = b.name;
    s.blocks.emplace(name, std::move(b));
  }

  TextFile f_;
  FrdResults r_;
  bool ended_ = false;
};

}  // namespace

FrdResults readCalculixFrd(const std::string& path) { return FrdReader(path).read(); }

FeStressSamples stressSamplesFromFrd(const FrdResults& frd, const FeBodyData& d, const std::string& frdPath,
                                     const std::string& owner) {
  static const std::array<const char*, 3> kDisp = {"D1", "D2", "D3"};
  static const std::array<const char*, 6> kStress = {"SXX", "SYY", "SZZ", "SXY", "SYZ", "SZX"};
  std::vector<const FrdStep*> steps;
  for (const FrdStep& s : frd.steps) {
    if (s.blocks.count("DISP") && s.blocks.count("STRESS")) steps.push_back(&s);
  }
  if (steps.empty()) {
    throw InputError(owner + ": " + frdPath + " has no step with both DISP and STRESS (CalculiX: *NODE FILE U and "
                     "*EL FILE S in the step)");
  }
  // the column of each named component in a block, or a message naming the missing one
  auto columns = [&](const FrdBlock& b, const auto& names, const FrdStep& s) {
    std::vector<int> col;
    for (const char* n : names) {
      int c = -1;
      for (std::size_t k = 0; k < b.components.size(); ++k) {
        if (b.components[k] == n) c = static_cast<int>(k);
      }
      if (c < 0) {
        throw InputError(owner + ": " + frdPath + ", step " + std::to_string(s.number) + ": block " + b.name +
                         " has no component " + n);
      }
      col.push_back(c);
    }
    return col;
  };
  const std::vector<int> dof = d.dofIndex();
  FeStressSamples out;
  out.displacement = MatX::Zero(d.numDofs(), static_cast<int>(steps.size()));
  out.stress = MatX::Zero(6 * d.numNodes(), static_cast<int>(steps.size()));
  for (std::size_t j = 0; j < steps.size(); ++j) {
    const FrdStep& s = *steps[j];
    const FrdBlock &u = s.blocks.at("DISP"), &sg = s.blocks.at("STRESS");
    const std::vector<int> cu = columns(u, kDisp, s), cs = columns(sg, kStress, s);
    for (int a = 0; a < d.numNodes(); ++a) {
      const auto iu = u.values.find(d.nodeIds[a]), is = sg.values.find(d.nodeIds[a]);
      if (iu == u.values.end() || is == sg.values.end()) {
        throw InputError(owner + ": " + frdPath + ", step " + std::to_string(s.number) + ": node " +
                         std::to_string(d.nodeIds[a]) + " of the body has no " +
                         (iu == u.values.end() ? "DISP" : "STRESS") + " value");
      }
      for (int k = 0; k < 3; ++k) out.displacement(dof[3 * a + k], static_cast<int>(j)) = iu->second[cu[k]];
      for (int k = 0; k < 6; ++k) out.stress(6 * a + k, static_cast<int>(j)) = is->second[cs[k]];
    }
  }
  return out;
}

}  // namespace flexmbd
