#include "tensegrity/tensegrity_structure.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/magnitude_checks.hpp"
#include "core/errors.hpp"
#include "tensegrity/cable_element.hpp"

namespace flexmbd {

namespace {

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string num(double x) {
  std::ostringstream os;
  os.precision(12);
  os << x;
  return os.str();
}

template <int D>
Eigen::Matrix<double, D, 1> nodeBlock(const VecX& x, int node) {
  return x.template segment<D>(D * node);
}

}  // namespace

TensegrityStructure::TensegrityStructure(int dimension) : dim_(dimension) {
  if (dim_ != 2 && dim_ != 3) {
    throw InputError("tensegrity: dimension must be 2 or 3, got " + std::to_string(dimension));
  }
  gravity_ = VecX::Zero(dim_);
}

void TensegrityStructure::requireBuild(const char* what) const {
  if (finalized_) throw InputError(std::string("tensegrity: ") + what + " after finalize()");
}

void TensegrityStructure::requireNode(int i, const std::string& owner) const {
  if (i < 0 || i >= numNodes()) {
    throw InputError(owner + ": node index " + std::to_string(i) + " out of range (0.." +
                     std::to_string(numNodes() - 1) + ")");
  }
}

int TensegrityStructure::addNode(const std::string& name, const VecX& position, double mass,
                                 std::vector<bool> fixed, const VecX& velocity) {
  requireBuild("addNode");
  const std::string who = "node " + quoted(name);
  if (name.empty()) throw InputError("node: the name must not be empty");
  if (findNode(name) >= 0) throw InputError(who + ": duplicate node name");
  if (position.size() != dim_ || velocity.size() != dim_) {
    throw InputError(who + ": position and velocity need " + std::to_string(dim_) + " components");
  }
  if (!position.allFinite() || !velocity.allFinite()) throw InputError(who + ": position and velocity must be finite");
  if (!(mass >= 0.0) || !std::isfinite(mass)) throw InputError(who + ": mass must be >= 0, got " + num(mass));
  if (fixed.empty()) fixed.assign(dim_, false);
  if (static_cast<int>(fixed.size()) != dim_) {
    throw InputError(who + ": fixed needs " + std::to_string(dim_) + " flags (one per axis)");
  }
  nodes_.push_back({name, position, velocity, mass, std::move(fixed)});
  return numNodes() - 1;
}

int TensegrityStructure::addStrut(const std::string& name, int nodeI, int nodeJ, double axialStiffness,
                                  double naturalLength, double mass, BarMassModel massModel, double radius) {
  requireBuild("addStrut");
  const std::string who = "strut " + quoted(name);
  requireNode(nodeI, who);
  requireNode(nodeJ, who);
  if (!(axialStiffness > 0.0) || !std::isfinite(axialStiffness)) {
    throw InputError(who + ": axial stiffness EA must be > 0, got " + num(axialStiffness));
  }
  if (!(naturalLength > 0.0) || !std::isfinite(naturalLength)) {
    throw InputError(who + ": natural length must be > 0, got " + num(naturalLength));
  }
  if (naturalLength < kMinPositiveMagnitude) {  // core/magnitude_checks.hpp
    throw InputError(who + ": natural length must be at least 1e-100, got " + num(naturalLength));
  }
  if (!(mass >= 0.0) || !std::isfinite(mass)) throw InputError(who + ": mass must be >= 0, got " + num(mass));
  if (!(radius >= 0.0) || !std::isfinite(radius)) throw InputError(who + ": radius must be >= 0, got " + num(radius));
  struts_.push_back({name, nodeI, nodeJ, axialStiffness, naturalLength, mass, massModel, radius});
  return numStruts() - 1;
}

int TensegrityStructure::addCable(const std::string& name, int nodeI, int nodeJ, double axialStiffness,
                                  double naturalLength, bool inextensible, double radius) {
  requireBuild("addCable");
  const std::string who = "cable " + quoted(name);
  requireNode(nodeI, who);
  requireNode(nodeJ, who);
  if (!inextensible && (!(axialStiffness > 0.0) || !std::isfinite(axialStiffness))) {
    throw InputError(who + ": axial stiffness EA must be > 0 (or the cable inextensible), got " +
                     num(axialStiffness));
  }
  if (!(naturalLength > 0.0) || !std::isfinite(naturalLength)) {
    throw InputError(who + ": natural length must be > 0, got " + num(naturalLength));
  }
  if (naturalLength < kMinPositiveMagnitude) {  // core/magnitude_checks.hpp
    throw InputError(who + ": natural length must be at least 1e-100, got " + num(naturalLength));
  }
  if (!(radius >= 0.0) || !std::isfinite(radius)) throw InputError(who + ": radius must be >= 0, got " + num(radius));
  cables_.push_back({name, nodeI, nodeJ, inextensible ? 0.0 : axialStiffness, naturalLength, inextensible, radius});
  return numCables() - 1;
}

void TensegrityStructure::addLoad(const std::string& name, int node, std::vector<TimeLawPtr> components) {
  requireBuild("addLoad");
  const std::string who = "load " + quoted(name);
  requireNode(node, who);
  if (static_cast<int>(components.size()) != dim_) {
    throw InputError(who + ": needs " + std::to_string(dim_) + " force components");
  }
  loads_.push_back({name, node, std::move(components)});
}

void TensegrityStructure::setGravity(const VecX& g) {
  requireBuild("setGravity");
  if (g.size() != dim_ || !g.allFinite()) {
    throw InputError("tensegrity: gravity needs " + std::to_string(dim_) + " finite components");
  }
  gravity_ = g;
}

void TensegrityStructure::setMaxStrutsPerNode(int n) {
  requireBuild("setMaxStrutsPerNode");
  if (n < 1) throw InputError("tensegrity: max_struts_per_node must be >= 1, got " + std::to_string(n));
  maxStrutsPerNode_ = n;
}

void TensegrityStructure::setCableNaturalLength(int c, double l0) {
  if (c < 0 || c >= numCables()) throw InputError("tensegrity: cable index out of range");
  if (!(l0 > 0.0) || !std::isfinite(l0)) {
    throw InputError("cable " + quoted(cables_[c].name) + ": natural length must be > 0, got " + num(l0));
  }
  cables_[c].naturalLength = l0;
}

void TensegrityStructure::setStrutNaturalLength(int s, double l0) {
  if (s < 0 || s >= numStruts()) throw InputError("tensegrity: strut index out of range");
  if (!(l0 > 0.0) || !std::isfinite(l0)) {
    throw InputError("strut " + quoted(struts_[s].name) + ": natural length must be > 0, got " + num(l0));
  }
  struts_[s].naturalLength = l0;
}

int TensegrityStructure::findNode(const std::string& name) const {
  for (int i = 0; i < numNodes(); ++i) {
    if (nodes_[i].name == name) return i;
  }
  return -1;
}

bool TensegrityStructure::allCablesInextensible() const {
  return std::all_of(cables_.begin(), cables_.end(), [](const TensegrityCable& c) { return c.inextensible; });
}

bool TensegrityStructure::anyCableInextensible() const {
  return std::any_of(cables_.begin(), cables_.end(), [](const TensegrityCable& c) { return c.inextensible; });
}

std::vector<MemberRef> TensegrityStructure::members() const {
  std::vector<MemberRef> out;
  for (int s = 0; s < numStruts(); ++s) out.push_back({true, s});
  for (int c = 0; c < numCables(); ++c) out.push_back({false, c});
  return out;
}

std::string TensegrityStructure::memberName(const MemberRef& m) const {
  return m.isStrut ? struts_.at(m.index).name : cables_.at(m.index).name;
}

std::pair<int, int> TensegrityStructure::memberNodes(const MemberRef& m) const {
  if (m.isStrut) return {struts_.at(m.index).nodeI, struts_.at(m.index).nodeJ};
  return {cables_.at(m.index).nodeI, cables_.at(m.index).nodeJ};
}

double TensegrityStructure::memberRadius(const MemberRef& m) const {
  return m.isStrut ? struts_.at(m.index).radius : cables_.at(m.index).radius;
}

void TensegrityStructure::finalize() {
  requireBuild("finalize");
  if (nodes_.empty()) throw InputError("tensegrity: the model has no nodes");
  // Members: distinct end nodes, non-zero initial length, no duplicate node pair.
  std::map<std::pair<int, int>, std::string> pairs;
  std::vector<int> strutsAt(numNodes(), 0);
  for (const MemberRef& m : members()) {
    const auto [i, j] = memberNodes(m);
    const std::string who = std::string(m.isStrut ? "strut " : "cable ") + quoted(memberName(m));
    if (i == j) throw InputError(who + ": joins node " + quoted(nodes_[i].name) + " to itself (expected two different nodes)");
    if ((nodes_[i].position - nodes_[j].position).norm() == 0.0) {
      throw InputError(who + ": its nodes " + quoted(nodes_[i].name) + " and " + quoted(nodes_[j].name) +
                       " coincide (zero initial length)");
    }
    const auto key = std::minmax(i, j);
    const auto [it, inserted] = pairs.emplace(key, who);
    if (!inserted) {
      throw InputError(who + ": joins the same nodes " + quoted(nodes_[i].name) + " and " + quoted(nodes_[j].name) +
                       " as " + it->second + " (at most one member per pair of nodes)");
    }
    if (m.isStrut) {
      for (int n : {i, j}) {
        if (++strutsAt[n] > maxStrutsPerNode_) {
          throw InputError(who + ": node " + quoted(nodes_[n].name) + " would be the end of " +
                           std::to_string(strutsAt[n]) + " struts (a tensegrity has at most " +
                           std::to_string(maxStrutsPerNode_) +
                           " per node; raise max_struts_per_node for a class-k tensegrity)");
        }
      }
    }
  }
  // Mass matrix (constant): nodal point masses plus the struts' own mass.
  const int n = numCoordinates();
  massFull_ = MatX::Zero(n, n);
  for (int i = 0; i < numNodes(); ++i) {
    massFull_.block(dim_ * i, dim_ * i, dim_, dim_).diagonal().array() += nodes_[i].mass;
  }
  for (const TensegrityStrut& s : struts_) {
    const int idx[2] = {s.nodeI, s.nodeJ};
    MatX me;
    if (dim_ == 2) {
      me = BarElement<2>(s.axialStiffness, s.naturalLength, s.mass, s.massModel).massMatrix();
    } else {
      me = BarElement<3>(s.axialStiffness, s.naturalLength, s.mass, s.massModel).massMatrix();
    }
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        massFull_.block(dim_ * idx[a], dim_ * idx[b], dim_, dim_) += me.block(dim_ * a, dim_ * b, dim_, dim_);
      }
    }
  }
  // Masses, stiffnesses and lengths within kMaxMagnitudeRatio of each other (massless nodes aside)
  std::vector<NamedMagnitude> masses, stiffnesses, lengths;
  for (int i = 0; i < numNodes(); ++i) masses.push_back({"node " + quoted(nodes_[i].name), massFull_(dim_ * i, dim_ * i)});
  for (const MemberRef& m : members()) {
    const std::string who = std::string(m.isStrut ? "strut " : "cable ") + quoted(memberName(m));
    const double ea = m.isStrut ? struts_[m.index].axialStiffness : cables_[m.index].axialStiffness;
    stiffnesses.push_back({who, ea});
    lengths.push_back({who, m.isStrut ? struts_[m.index].naturalLength : cables_[m.index].naturalLength});
  }
  checkMagnitudeSpread("mass", masses);
  checkMagnitudeSpread("axial stiffness EA", stiffnesses);
  checkMagnitudeSpread("natural length", lengths);
  // Free coordinates; each must carry mass.
  free_.clear();
  freeIndexOf_.assign(n, -1);
  for (int i = 0; i < numNodes(); ++i) {
    const TensegrityNode& nd = nodes_[i];
    for (int a = 0; a < dim_; ++a) {
      const int k = dim_ * i + a;
      if (nd.fixed[a]) {
        if (nd.velocity[a] != 0.0) {
          throw InputError("node " + quoted(nd.name) + ": a fixed coordinate must have zero initial velocity, got " +
                           num(nd.velocity[a]));
        }
        continue;
      }
      if (!(massFull_(k, k) > 0.0)) {
        throw InputError("node " + quoted(nd.name) +
                         ": has no mass (no nodal mass and no strut mass) and is not fixed (expected a mass > 0 or "
                         "\"fixed\": true)");
      }
      freeIndexOf_[k] = static_cast<int>(free_.size());
      free_.push_back(k);
    }
  }
  const int nf = numFreeCoordinates();
  massFree_.resize(nf, nf);
  for (int a = 0; a < nf; ++a) {
    for (int b = 0; b < nf; ++b) massFree_(a, b) = massFull_(free_[a], free_[b]);
  }
  finalized_ = true;
}

VecX TensegrityStructure::initialPositions() const {
  VecX x(numCoordinates());
  for (int i = 0; i < numNodes(); ++i) x.segment(dim_ * i, dim_) = nodes_[i].position;
  return x;
}

VecX TensegrityStructure::initialVelocities() const {
  VecX v(numCoordinates());
  for (int i = 0; i < numNodes(); ++i) v.segment(dim_ * i, dim_) = nodes_[i].velocity;
  return v;
}

VecX TensegrityStructure::expand(const VecX& freePart, const VecX& fullTemplate) const {
  VecX full = fullTemplate;
  for (int a = 0; a < numFreeCoordinates(); ++a) full[free_[a]] = freePart[a];
  return full;
}

VecX TensegrityStructure::restrict(const VecX& full) const {
  VecX r(numFreeCoordinates());
  for (int a = 0; a < numFreeCoordinates(); ++a) r[a] = full[free_[a]];
  return r;
}

VecX TensegrityStructure::externalForces(double t) const {
  // Gravity: the consistent load of a uniform field, M [g; g; ...] (for a bar with
  // linear shape functions this is m g / 2 per end node, lumped or consistent).
  VecX G(numCoordinates());
  for (int i = 0; i < numNodes(); ++i) G.segment(dim_ * i, dim_) = gravity_;
  return massFull_ * G + loadForces(t);
}

VecX TensegrityStructure::loadForces(double t) const {
  VecX f = VecX::Zero(numCoordinates());
  for (const TensegrityLoad& l : loads_) {
    for (int a = 0; a < dim_; ++a) {
      if (l.components[a]) f[dim_ * l.node + a] += l.components[a]->evaluate(t).f;
    }
  }
  return f;
}

template <int D>
void TensegrityStructure::addInternalForces(const VecX& x, VecX& g) const {
  for (const TensegrityStrut& s : struts_) {
    const BarElement<D> bar(s.axialStiffness, s.naturalLength, s.mass, s.massModel);
    const auto xi = nodeBlock<D>(x, s.nodeI), xj = nodeBlock<D>(x, s.nodeJ);
    const auto ge = bar.internalForces(xi, xj);
    g.template segment<D>(D * s.nodeI) += ge.template head<D>();
    g.template segment<D>(D * s.nodeJ) += ge.template tail<D>();
  }
  for (const TensegrityCable& c : cables_) {
    if (c.inextensible) continue;
    const CableElement<D> cable(c.axialStiffness, c.naturalLength, false);
    const auto xi = nodeBlock<D>(x, c.nodeI), xj = nodeBlock<D>(x, c.nodeJ);
    const double tau = cable.tension(cable.length(xi, xj));
    if (tau == 0.0) continue;
    const auto ge = (tau * cable.lengthGradient(xi, xj)).eval();
    g.template segment<D>(D * c.nodeI) += ge.template head<D>();
    g.template segment<D>(D * c.nodeJ) += ge.template tail<D>();
  }
}

VecX TensegrityStructure::internalForces(const VecX& x) const {
  VecX g = VecX::Zero(numCoordinates());
  if (dim_ == 2) {
    addInternalForces<2>(x, g);
  } else {
    addInternalForces<3>(x, g);
  }
  return g;
}

VecX TensegrityStructure::cableLengths(const VecX& x) const {
  VecX l(numCables());
  for (int c = 0; c < numCables(); ++c) {
    l[c] = (x.segment(dim_ * cables_[c].nodeJ, dim_) - x.segment(dim_ * cables_[c].nodeI, dim_)).norm();
  }
  return l;
}

double TensegrityStructure::strutLength(const VecX& x, int i) const {
  const TensegrityStrut& st = struts_.at(i);
  return (x.segment(dim_ * st.nodeJ, dim_) - x.segment(dim_ * st.nodeI, dim_)).norm();
}

double TensegrityStructure::strutForce(const VecX& x, int i) const {
  const TensegrityStrut& st = struts_.at(i);
  // N = EA (l - l0) / l0 (BarElement::internalForces; Doc001), independent of the dimension.
  return st.axialStiffness * (strutLength(x, i) - st.naturalLength) / st.naturalLength;
}

VecX TensegrityStructure::elasticCableTensions(const VecX& x) const {
  const VecX l = cableLengths(x);
  VecX tau(numCables());
  for (int c = 0; c < numCables(); ++c) {
    const TensegrityCable& cb = cables_[c];
    // tau = (EA/l0) max(l - l0, 0) (CableElement::tension; Doc001, eq. 7), independent of the dimension.
    tau[c] = cb.inextensible ? 0.0 : cb.axialStiffness * std::max(l[c] - cb.naturalLength, 0.0) / cb.naturalLength;
  }
  return tau;
}

std::vector<std::pair<int, double>> TensegrityStructure::cableGradientEntries(const VecX& x, int c) const {
  const TensegrityCable& cb = cables_.at(c);
  const VecX d = x.segment(dim_ * cb.nodeJ, dim_) - x.segment(dim_ * cb.nodeI, dim_);
  const VecX e = d / d.norm();  // b_c = [-e; e] (CableElement::lengthGradient; Doc001, eq. 6)
  std::vector<std::pair<int, double>> out;
  out.reserve(2 * dim_);
  for (int a = 0; a < dim_; ++a) {
    const int ki = freeIndexOf_[dim_ * cb.nodeI + a], kj = freeIndexOf_[dim_ * cb.nodeJ + a];
    if (ki >= 0) out.emplace_back(ki, -e[a]);
    if (kj >= 0) out.emplace_back(kj, e[a]);
  }
  return out;
}

RowVecX TensegrityStructure::cableGradientFree(const VecX& x, int c) const {
  RowVecX b = RowVecX::Zero(numFreeCoordinates());
  for (const auto& [k, val] : cableGradientEntries(x, c)) b[k] += val;
  return b;
}

double TensegrityStructure::kineticEnergy(const VecX& v) const { return 0.5 * v.dot(massFull_ * v); }

double TensegrityStructure::potentialEnergy(const VecX& x) const {
  double u = 0.0;
  for (const TensegrityStrut& s : struts_) {
    const double l = (x.segment(dim_ * s.nodeJ, dim_) - x.segment(dim_ * s.nodeI, dim_)).norm();
    u += 0.5 * s.axialStiffness * (l - s.naturalLength) * (l - s.naturalLength) / s.naturalLength;
  }
  const VecX l = cableLengths(x);
  for (int c = 0; c < numCables(); ++c) {
    const TensegrityCable& cb = cables_[c];
    if (cb.inextensible) continue;
    const double e = std::max(l[c] - cb.naturalLength, 0.0);
    u += 0.5 * cb.axialStiffness * e * e / cb.naturalLength;
  }
  VecX G(numCoordinates());
  for (int i = 0; i < numNodes(); ++i) G.segment(dim_ * i, dim_) = gravity_;
  u -= x.dot(massFull_ * G);
  return u;
}

}  // namespace flexmbd
