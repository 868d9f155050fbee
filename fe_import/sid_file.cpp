#include "fe_import/sid_file.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/errors.hpp"
#include "fe_import/fe_text.hpp"

namespace flexmbd {

namespace {

using feread::TextFile;

// ----- writing ---------------------------------------------------------------------

void writeNumber(std::ostream& out, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out << buf;
}

/// "    m1( 2, 3, 1) = v" for the non-zero entries of one term (`extra`: trailing indices).
void writeTerm(std::ostream& out, const std::string& term, const MatX& A, const std::vector<int>& extra,
               int structure) {
  for (int i = 0; i < A.rows(); ++i) {
    for (int j = 0; j < A.cols(); ++j) {
      if (A(i, j) == 0.0) continue;
      if (structure == SidTaylor::Symmetric && j > i) continue;
      if (structure == SidTaylor::Diagonal && j != i) continue;
      out << "    " << term << "(" << i + 1 << ", " << j + 1;
      for (int e : extra) out << ", " << e + 1;
      out << ") = ";
      writeNumber(out, A(i, j));
      out << "\n";
    }
  }
}

void writeTaylor(std::ostream& out, const SidTaylor& t) {
  out << t.name << "\n    order = " << t.order << "\n    nrow = " << t.nrow << "\n    ncol = " << t.ncol
      << "\n    nq = " << t.nq << "\n    nqn = " << t.nqn << "\n    structure = " << t.structure << "\n";
  if (t.structure != SidTaylor::Zero) writeTerm(out, "m0", t.m0, {}, t.structure);
  for (std::size_t k = 0; k < t.m1.size(); ++k) writeTerm(out, "m1", t.m1[k], {static_cast<int>(k)}, SidTaylor::Full);
  for (std::size_t kl = 0; kl < t.m2.size(); ++kl) {
    const int k = static_cast<int>(kl) % t.nqn, l = static_cast<int>(kl) / t.nqn;
    writeTerm(out, "m2", t.m2[kl], {k, l}, SidTaylor::Full);
  }
  out << "end " << t.name << "\n";
}

// ----- reading ---------------------------------------------------------------------

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// Caps on a Taylor object's size: a header that would allocate more is a malformed file.
constexpr long kMaxEntries = 200'000'000;

class SidReader {
 public:
  explicit SidReader(const std::string& path) : f_(path) {}

  SidData read() {
    expectLine("part");
    expectLine("new modal");
    SidData s;
    expectLine("refmod");
    readRefmod(s);
    const std::string frame = lower(nextLine("\"new frame\""));
    if (frame != "new frame" && frame != "frame") f_.fail("found '" + line_ + "'; expected \"new frame\"");
    readFrame(s);
    readBlocks(s);
    expectLine("end part");
    std::string rest;
    if (nextContent(rest)) f_.fail("found '" + rest + "' after \"end part\"; expected the end of the file");
    return s;
  }

 private:
  /// The next line that is not blank or a comment, trimmed; false at the end of the file.
  bool nextContent(std::string& line) {
    while (f_.next(line)) {
      line = feread::trimmed(line);
      if (!line.empty() && line[0] != '!' && line[0] != '#') return true;
    }
    return false;
  }
  const std::string& nextLine(const std::string& expected) {
    if (!nextContent(line_)) {
      throw InputError(f_.path() + ": the file ends after line " + std::to_string(f_.lineNumber()) + "; expected " +
                       expected);
    }
    return line_;
  }
  void expectLine(const std::string& want) {
    if (lower(nextLine("\"" + want + "\"")) != want) f_.fail("found '" + line_ + "'; expected \"" + want + "\"");
  }
  /// "key = value" of the current line (key lower-cased, both trimmed), or false.
  bool keyValue(std::string& key, std::string& value) const {
    const std::size_t eq = line_.find('=');
    if (eq == std::string::npos) return false;
    key = lower(feread::trimmed(line_.substr(0, eq)));
    value = feread::trimmed(line_.substr(eq + 1));
    return true;
  }
  int integer(const std::string& v, const std::string& what, long lo, long hi) {
    const long x = feread::integerField(f_, v, what);
    if (x < lo || x > hi) {
      f_.fail(what + " is " + v + "; expected " + std::to_string(lo) + " to " + std::to_string(hi));
    }
    return static_cast<int>(x);
  }

  void readRefmod(SidData& s) {
    bool haveMass = false;
    int n = -1;
    std::map<int, std::string> names;
    std::string key, value;
    while (lower(nextLine("\"end refmod\"")) != "end refmod") {
      if (!keyValue(key, value)) f_.fail("found '" + line_ + "'; expected 'key = value' or \"end refmod\"");
      if (key == "mass") {
        s.mass = feread::realField(f_, value, "mass");
        haveMass = true;
      } else if (key == "nelastq") {
        n = integer(value, "nelastq", 0, 100000);
      } else if (key.rfind("ielastq(", 0) == 0 && key.back() == ')') {
        const int k = integer(key.substr(8, key.size() - 9), "the index of ielastq", 1, 100000);
        if (!names.emplace(k, value).second) f_.fail("ielastq(" + std::to_string(k) + ") is given twice");
      } else {
        f_.fail("unknown key '" + key + "' in refmod; expected mass, nelastq or ielastq(i)");
      }
    }
    if (!haveMass || n < 0) f_.fail("refmod ends without " + std::string(haveMass ? "nelastq" : "mass"));
    for (const auto& [k, name] : names) {
      if (k > n) f_.fail("refmod names ielastq(" + std::to_string(k) + ") of nelastq = " + std::to_string(n));
    }
    for (int k = 1; k <= n; ++k) {
      auto it = names.find(k);
      s.modeNames.push_back(it == names.end() ? "q" + std::to_string(k) : it->second);
    }
  }

  void readFrame(SidData& s) {
    std::string key, value;
    while (lower(nextLine("\"new node = ...\" or \"end frame\"")) != "end frame") {
      if (!keyValue(key, value) || key != "new node") {
        f_.fail("found '" + line_ + "'; expected \"new node = <name>\" or \"end frame\"");
      }
      SidNode nd;
      nd.name = value;
      const std::string where = "node " + value;
      while (lower(nextLine("\"end node\"")) != "end node") {
        if (keyValue(key, value)) {
          if (key != "rframe") f_.fail("unknown key '" + key + "' in " + where + "; expected rframe");
          nd.rframe = value;
          continue;
        }
        const std::string name = lower(line_);
        SidTaylor* t = name == "origin" ? &nd.origin : name == "phi" ? &nd.phi : name == "psi" ? &nd.psi
                     : name == "ap"     ? &nd.ap
                                        : nullptr;
        if (!t) f_.fail("found '" + line_ + "' in " + where + "; expected origin, phi, psi, AP or \"end node\"");
        if (!t->name.empty()) f_.fail(where + " gives " + line_ + " twice");
        *t = readTaylor(line_);
      }
      for (const auto* req : {&nd.origin, &nd.phi, &nd.psi}) {
        if (req->name.empty()) {
          f_.fail(where + " ends without its " +
                  std::string(req == &nd.origin ? "origin" : req == &nd.phi ? "phi" : "psi") +
                  " (expected origin, phi and psi in every node)");
        }
      }
      s.nodes.push_back(std::move(nd));
    }
  }

  void readBlocks(SidData& s) {
    static const char* kNames[] = {"mdCM", "J", "Ct", "Cr", "Me", "Gr", "Ge", "Oe", "ksigma", "Ke", "De"};
    const std::vector<SidTaylor*> blocks = s.blocks();
    while (lower(nextLine("a Taylor block or \"end modal\"")) != "end modal") {
      int which = -1;
      for (int b = 0; b < 11; ++b) {
        if (lower(line_) == lower(kNames[b])) which = b;
      }
      if (which < 0) {
        f_.fail("found '" + line_ + "'; expected one of mdCM, J, Ct, Cr, Me, Gr, Ge, Oe, ksigma, Ke, De or \"end modal\"");
      }
      if (!blocks[which]->name.empty()) f_.fail("block " + std::string(kNames[which]) + " is given twice");
      *blocks[which] = readTaylor(kNames[which]);
    }
    for (const char* required : {"mdCM", "J", "Cr", "Me", "Gr", "Ke"}) {
      for (int b = 0; b < 11; ++b) {
        if (kNames[b] == std::string(required) && blocks[b]->name.empty()) {
          f_.fail("the modal part ends without block " + std::string(required) +
                  " (required: mdCM, J, Cr, Me, Gr, Ke; optional: Ct, Ge, Oe, ksigma, De)");
        }
      }
    }
  }

  /// A Taylor object after its name line: the header, then the entries, then "end <name>".
  SidTaylor readTaylor(const std::string& name) {
    std::map<std::string, int> header;
    std::string key, value;
    const std::string endLine = "end " + lower(name);
    SidTaylor t;
    bool sized = false;
    std::set<std::vector<int>> seen;
    while (lower(nextLine("\"end " + name + "\"")) != endLine) {
      if (!keyValue(key, value)) f_.fail("found '" + line_ + "' in " + name + "; expected 'key = value'");
      if (key.size() > 2 && key[0] == 'm' && key[2] == '(') {
        if (!sized) sized = sizeTaylor(name, header, t);
        readEntry(name, key, value, t, seen);
        continue;
      }
      static const std::set<std::string> known = {"order", "nrow", "ncol", "nq", "nqn", "structure"};
      if (!known.count(key)) {
        f_.fail("unknown key '" + key + "' in " + name + "; expected order, nrow, ncol, nq, nqn, structure or entries "
                "m0(i, j), m1(i, j, k), m2(i, j, k, l)");
      }
      if (sized) f_.fail("key '" + key + "' in " + name + " after its entries; expected the header first");
      if (!header.emplace(key, integer(value, name + " " + key, 0, 10'000'000)).second) {
        f_.fail("key '" + key + "' is given twice in " + name);
      }
    }
    if (!sized) sizeTaylor(name, header, t);
    t.name = name;
    return t;
  }

  bool sizeTaylor(const std::string& name, const std::map<std::string, int>& h, SidTaylor& t) {
    for (const char* k : {"order", "nrow", "ncol", "structure"}) {
      if (!h.count(k)) f_.fail(name + " has no '" + k + "' before its entries; expected order, nrow, ncol, structure");
    }
    const auto get = [&](const char* k) { return h.count(k) ? h.at(k) : 0; };
    const int order = get("order"), structure = get("structure");
    if (order > 2) f_.fail(name + " has order " + std::to_string(order) + "; expected 0, 1 or 2");
    if (structure > 3) f_.fail(name + " has structure " + std::to_string(structure) + "; expected 0 to 3");
    if (order >= 1 && !h.count("nq")) f_.fail(name + " has order " + std::to_string(order) + " but no nq");
    if (order == 2 && !h.count("nqn")) f_.fail(name + " has order 2 but no nqn");
    const long rows = get("nrow"), cols = get("ncol"), nq = order >= 1 ? get("nq") : 0;
    const long nqn = order == 2 ? get("nqn") : 0;
    if (rows * cols * (1 + nq + nqn * nqn) > kMaxEntries) {
      f_.fail(name + " is " + std::to_string(rows) + " x " + std::to_string(cols) + " with nq = " + std::to_string(nq) +
              ": more than " + std::to_string(kMaxEntries) + " entries; expected a reduced body");
    }
    if ((structure == SidTaylor::Symmetric || structure == SidTaylor::Diagonal) && rows != cols) {
      f_.fail(name + " has structure " + std::to_string(structure) + " (symmetric or diagonal) but is " +
              std::to_string(rows) + " x " + std::to_string(cols) + "; expected a square matrix");
    }
    t = SidTaylor::zero(name, order, static_cast<int>(rows), static_cast<int>(cols), static_cast<int>(nq), structure);
    t.nq = static_cast<int>(nq);
    t.nqn = static_cast<int>(nqn);
    if (order == 2) t.m2.assign(static_cast<std::size_t>(nqn * nqn), MatX::Zero(rows, cols));
    return true;
  }

  void readEntry(const std::string& name, const std::string& key, const std::string& value, SidTaylor& t,
                 std::set<std::vector<int>>& seen) {
    const int term = key[1] - '0';
    if (term < 0 || term > t.order || key.back() != ')') {
      f_.fail("entry '" + key + "' in " + name + " of order " + std::to_string(t.order) + "; expected m0(i, j)" +
              (t.order >= 1 ? ", m1(i, j, k)" : "") + (t.order >= 2 ? ", m2(i, j, k, l)" : ""));
    }
    const std::vector<std::string> fields = feread::splitFields(key.substr(3, key.size() - 4), ",");
    if (static_cast<int>(fields.size()) != 2 + term) {
      f_.fail("entry '" + key + "' in " + name + " has " + std::to_string(fields.size()) + " indices; expected " +
              std::to_string(2 + term));
    }
    const int limits[4] = {t.nrow, t.ncol, term == 1 ? t.nq : t.nqn, t.nqn};
    std::vector<int> at{term};
    for (std::size_t i = 0; i < fields.size(); ++i) {
      at.push_back(integer(fields[i], "index " + std::to_string(i + 1) + " of " + key + " in " + name, 1, limits[i]) - 1);
    }
    const double v = feread::realField(f_, value, key + " in " + name);
    if (!seen.insert(at).second) f_.fail("entry " + key + " of " + name + " is given twice");
    const int i = at[1], j = at[2];
    if (term == 0) {
      if (t.structure == SidTaylor::Zero) f_.fail(name + " has structure 0 (zero) but gives " + key);
      if (t.structure == SidTaylor::Diagonal && i != j) f_.fail(name + " is diagonal (structure 1) but gives " + key);
      if (t.structure == SidTaylor::Symmetric && j > i) {
        f_.fail(name + " is symmetric (structure 2) and stores the lower triangle, but gives " + key +
                "; expected i >= j");
      }
      t.m0(i, j) = v;
      if (t.structure == SidTaylor::Symmetric) t.m0(j, i) = v;
    } else if (term == 1) {
      t.m1[at[3]](i, j) = v;
    } else {
      t.m2[at[3] + t.nqn * at[4]](i, j) = v;
    }
  }

  TextFile f_;
  std::string line_;
};

}  // namespace

void writeSid(const SidData& s, std::ostream& out) {
  out << "part\nnew modal\nrefmod\n    mass = ";
  writeNumber(out, s.mass);
  out << "\n    nelastq = " << s.numElastic() << "\n";
  for (int k = 0; k < s.numElastic(); ++k) out << "    ielastq(" << k + 1 << ") = " << s.modeNames[k] << "\n";
  out << "end refmod\nnew frame\n";
  for (const SidNode& nd : s.nodes) {
    out << "new node = " << nd.name << "\n    rframe = " << nd.rframe << "\n";
    for (const SidTaylor* t : {&nd.origin, &nd.phi, &nd.psi, &nd.ap}) writeTaylor(out, *t);
    out << "end node\n";
  }
  out << "end frame\n";
  for (const SidTaylor* t : s.blocks()) {
    if (!t->name.empty()) writeTaylor(out, *t);
  }
  out << "end modal\nend part\n";
}

void writeSidFile(const SidData& sid, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot be written (check the folder exists and is writable)");
  writeSid(sid, out);
  out.flush();
  if (!out) throw InputError(path + ": writing failed (disk full?)");
}

SidData readSidFile(const std::string& path) { return SidReader(path).read(); }

}  // namespace flexmbd
