#include "fe_import/fe_inp.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <utility>

#include "core/errors.hpp"
#include "fe_import/fe_text.hpp"

namespace flexmbd::feread {

namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

/// A keyword line "*Name, p1=v1, flag": the name and the parameters (names upper case).
struct Keyword {
  std::string name;
  std::map<std::string, std::string> params;
};

Keyword parseKeyword(const std::string& line) {
  const std::vector<std::string> f = splitFields(line.substr(1), ",");
  Keyword k;
  k.name = upper(f[0]);
  for (size_t i = 1; i < f.size(); ++i) {
    const auto eq = f[i].find('=');
    if (eq == std::string::npos) {
      k.params[upper(f[i])] = "";
    } else {
      k.params[upper(trimmed(f[i].substr(0, eq)))] = trimmed(f[i].substr(eq + 1));
    }
  }
  return k;
}

/// Nodes of the element types read: solids C3D<n> with optional suffix letters (C3D8R);
/// beams B31, B32, B33 (suffix H); shells S3, S3R, S4, S4R, S8R (6 DOF per node, not the
/// 5-DOF S4R5 family); the point elements MASS and ROTARYI. -1 for other types.
int elementNodeCount(const std::string& type) {
  static const std::map<std::string, int> structural = {
      {"B31", 2}, {"B32", 3}, {"B33", 2}, {"B31H", 2}, {"B32H", 3}, {"B33H", 2}, {"S3", 3},     {"S3R", 3},
      {"S4", 4},  {"S4R", 4}, {"S8R", 8}, {"MASS", 1}, {"ROTARYI", 1}};
  static const std::map<std::string, int> counts = {{"4", 4}, {"6", 6}, {"8", 8}, {"10", 10}, {"15", 15}, {"20", 20}};
  const std::string t = upper(type);
  const auto s = structural.find(t);
  if (s != structural.end()) return s->second;
  if (t.rfind("C3D", 0) != 0) return -1;
  size_t e = 3;
  while (e < t.size() && std::isdigit(static_cast<unsigned char>(t[e]))) ++e;
  for (size_t i = e; i < t.size(); ++i) {
    if (std::string("RIHMT").find(t[i]) == std::string::npos) return -1;
  }
  const auto it = counts.find(t.substr(3, e - 3));
  return it == counts.end() ? -1 : it->second;
}

/// A node label used before every node is known: resolved at the end.
struct PendingLabel {
  long label;
  int line;
};

struct PendingElement {
  FeElement element;
  std::vector<PendingLabel> labels;
};

enum class Section { None, Node, Element, Nset };

class InpReader {
 public:
  InpReader(const std::string& path, InpElements kinds) : f_(path), kinds_(kinds) {}

  FeBodyData read() {
    std::string line;
    std::vector<std::string> pendingFields;  // an element continued over lines
    int pendingLine = 0;
    while (f_.next(line)) {
      const std::string t = trimmed(line);
      if (t.empty() || t.rfind("**", 0) == 0) continue;
      if (t[0] == '*') {
        if (!pendingFields.empty())
          f_.failAt(pendingLine,
                    "element " + pendingFields[0] + " has too few nodes; expected " + std::to_string(elementNodes_));
        startSection(parseKeyword(t));
        continue;
      }
      switch (section_) {
        case Section::Node:
          readNode(t);
          break;
        case Section::Element: {
          const std::vector<std::string> f = splitFields(t, ",");
          if (pendingFields.empty()) pendingLine = f_.lineNumber();
          pendingFields.insert(pendingFields.end(), f.begin(), f.end());
          if (static_cast<int>(pendingFields.size()) >= elementNodes_ + 1) {
            readElement(pendingFields, pendingLine);
            pendingFields.clear();
          }
          break;
        }
        case Section::Nset:
          readSetLine(t);
          break;
        case Section::None:
          break;  // data of a keyword not read
      }
    }
    if (!pendingFields.empty())
      f_.failAt(pendingLine,
                "element " + pendingFields[0] + " has too few nodes; expected " + std::to_string(elementNodes_));
    return finish();
  }

 private:
  void startSection(const Keyword& k) {
    section_ = Section::None;
    setName_.clear();
    if (k.name == "INCLUDE") {
      f_.fail("*" + k.name + " is not followed; expected the whole model in one file (the nodes, elements and sets)");
    }
    if (k.name == "NODE") {
      section_ = Section::Node;
      if (k.params.count("NSET")) setName_ = k.params.at("NSET");
    } else if (k.name == "ELEMENT") {
      section_ = Section::Element;
      const auto it = k.params.find("TYPE");
      if (it == k.params.end()) f_.fail("*Element without type=; expected e.g. *Element, type=C3D8");
      elementType_ = it->second;
      elementNodes_ = elementNodeCount(elementType_);
      const bool solid = upper(elementType_).rfind("C3D", 0) == 0;
      if (elementNodes_ >= 0 && !solid && kinds_ == InpElements::Solids) {
        f_.fail("element type '" + elementType_ +
                "' is not read in a CalculiX deck; expected solids C3D4, C3D6, C3D8, C3D10, C3D15 or C3D20 (CalculiX "
                "expands beams and shells into solids with nodes of its own, which its matrices use)");
      }
      if (elementNodes_ < 0) {
        f_.fail(
            "element type '" + elementType_ +
            "' is not an element read here; expected a solid C3D4, C3D6, C3D8, C3D10, C3D15 or C3D20 (suffixes R, "
            "I, H, M, T allowed), a beam B31, B32, B33 (suffix H), a shell S3, S3R, S4, S4R, S8R, MASS or ROTARYI");
      }
    } else if (k.name == "NSET") {
      section_ = Section::Nset;
      const auto it = k.params.find("NSET");
      if (it == k.params.end() || it->second.empty()) f_.fail("*Nset without nset=NAME; expected a set name");
      setName_ = it->second;
      generate_ = k.params.count("GENERATE") > 0;
      sets_[setName_];  // an empty set is still a set
    }
  }

  void readNode(const std::string& t) {
    const std::vector<std::string> f = splitFields(t, ",");
    if (f.size() != 4) {
      f_.fail("a node line has " + std::to_string(f.size()) + " fields; expected 'label, x, y, z'");
    }
    const long label = integerField(f_, f[0], "the node label");
    if (label < 1) f_.fail("node label " + std::to_string(label) + "; expected a positive label");
    if (!nodeLine_.emplace(label, f_.lineNumber()).second) {
      f_.fail("node " + std::to_string(label) + " is defined twice (first on line " +
              std::to_string(nodeLine_.at(label)) + "); expected unique labels (one instance)");
    }
    Vec3 x;
    for (int k = 0; k < 3; ++k)
      x[k] = realField(f_, f[k + 1], std::string("coordinate ") + "xyz"[k] + " of node " + f[0]);
    nodes_.emplace_back(label, x);
    if (!setName_.empty()) sets_[setName_].push_back({label, f_.lineNumber()});
  }

  void readElement(const std::vector<std::string>& f, int line) {
    if (static_cast<int>(f.size()) != elementNodes_ + 1) {
      f_.failAt(line, "element " + f[0] + " has " + std::to_string(f.size() - 1) + " nodes; expected " +
                          std::to_string(elementNodes_) + " for type " + elementType_);
    }
    PendingElement e;
    e.element.type = elementType_;
    e.element.id = static_cast<int>(integerField(f_, f[0], "the element label"));
    if (!elementLine_.emplace(e.element.id, line).second) {
      f_.failAt(line, "element " + f[0] + " is defined twice (first on line " +
                          std::to_string(elementLine_.at(e.element.id)) + "); expected unique labels");
    }
    for (size_t i = 1; i < f.size(); ++i)
      e.labels.push_back({integerField(f_, f[i], "node " + std::to_string(i) + " of element " + f[0]), line});
    elements_.push_back(std::move(e));
  }

  void readSetLine(const std::string& t) {
    const std::vector<std::string> f = splitFields(t, ",");
    std::vector<PendingLabel>& set = sets_[setName_];
    if (generate_) {
      if (f.size() < 2 || f.size() > 3)
        f_.fail("a generate line of set " + setName_ + " has " + std::to_string(f.size()) +
                " fields; expected 'first, last[, step]'");
      const long a = integerField(f_, f[0], "the first node"), b = integerField(f_, f[1], "the last node");
      const long s = f.size() == 3 ? integerField(f_, f[2], "the step") : 1;
      if (s < 1 || b < a)
        f_.fail("set " + setName_ + " generates from " + f[0] + " to " + f[1] + " by " + std::to_string(s) +
                "; expected first <= last and a positive step");
      for (long l = a; l <= b; l += s) set.push_back({l, f_.lineNumber()});
      return;
    }
    for (const std::string& s : f) {
      if (s.empty()) f_.fail("an empty field in set " + setName_ + "; expected node labels separated by commas");
      set.push_back({integerField(f_, s, "a node label of set " + setName_), f_.lineNumber()});
    }
  }

  FeBodyData finish() {
    FeBodyData d;
    std::sort(nodes_.begin(), nodes_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::map<long, int> index;
    for (const auto& n : nodes_) {
      index[n.first] = d.numNodes();
      d.nodeIds.push_back(static_cast<int>(n.first));
      d.coordinates.push_back(n.second);
    }
    if (d.nodeIds.empty()) throw InputError(f_.path() + ": no *Node data; expected the body's nodes");
    const auto resolve = [&](const PendingLabel& p, const std::string& user) {
      const auto it = index.find(p.label);
      if (it == index.end())
        f_.failAt(p.line, user + " names node " + std::to_string(p.label) + ", which no *Node line defines");
      return it->second;
    };
    for (PendingElement& e : elements_) {
      for (const PendingLabel& p : e.labels)
        e.element.nodes.push_back(resolve(p, "element " + std::to_string(e.element.id)));
      d.elements.push_back(std::move(e.element));
    }
    for (const auto& s : sets_) {
      std::vector<int>& out = d.nodeSets[s.first];
      for (const PendingLabel& p : s.second) out.push_back(resolve(p, "node set " + s.first));
    }
    return d;
  }

  TextFile f_;
  InpElements kinds_;
  Section section_ = Section::None;
  std::string setName_, elementType_;
  int elementNodes_ = 0;
  bool generate_ = false;
  std::vector<std::pair<long, Vec3>> nodes_;
  std::map<long, int> nodeLine_, elementLine_;
  std::vector<PendingElement> elements_;
  std::map<std::string, std::vector<PendingLabel>> sets_;
};

}  // namespace

FeBodyData readInpMesh(const std::string& path, InpElements kinds) {
  FeBodyData d = InpReader(path, kinds).read();
  d.source = path;
  return d;
}

}  // namespace flexmbd::feread
