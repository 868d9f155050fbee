#include "core/system.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <set>

#include "core/errors.hpp"
#include "core/ground.hpp"
#include "core/magnitude_checks.hpp"

namespace flexmbd {

System::System() { bodies_.push_back(std::make_unique<Ground>()); }
System::~System() = default;
System::System(System&&) noexcept = default;
System& System::operator=(System&&) noexcept = default;

void System::requireBuildPhase(const std::string& what) const {
  if (finalized_) {
    throw InputError("cannot add " + what + ": the system is finalized (add everything before finalize())");
  }
}

void System::requireFinalized(const char* what) const {
  if (!finalized_) throw InputError(std::string(what) + ": call finalize() first");
}

void System::checkNewName(const std::string& name, const std::string& kind) const {
  if (name.empty()) throw InputError(kind + ": the name must not be empty");
  for (const auto& b : bodies_) {
    if (b->name() == name) throw InputError(kind + " '" + name + "': duplicate name (a body already has it)");
  }
  for (const auto& c : constraints_) {
    if (c->name() == name) {
      throw InputError(kind + " '" + name + "': duplicate name (" + (c->isDriver() ? "a driver" : "a joint") +
                       " already has it)");
    }
  }
  for (const auto& f : forces_) {
    if (f->name() == name) throw InputError(kind + " '" + name + "': duplicate name (a force already has it)");
  }
}

void System::checkBody(BodyIndex i, const std::string& user) const {
  if (i.value < 0 || i.value >= numBodies()) {
    throw InputError(user + ": body index " + std::to_string(i.value) + " does not exist");
  }
}

BodyIndex System::addBody(std::unique_ptr<Body> body) {
  requireBuildPhase("body");
  if (!body) throw InputError("addBody: null body");
  checkNewName(body->name(), "body");
  bodies_.push_back(std::move(body));
  return BodyIndex(numBodies() - 1);
}

ConstraintIndex System::addConstraint(std::unique_ptr<Constraint> c) {
  requireBuildPhase("constraint");
  if (!c) throw InputError("addConstraint: null constraint");
  const std::string kind = c->isDriver() ? "driver" : "joint";
  checkNewName(c->name(), kind);
  if (c->bodies().size() > static_cast<size_t>(BodyStates::kMaxBodies)) {
    throw InputError(kind + " '" + c->name() + "': connects " + std::to_string(c->bodies().size()) +
                     " bodies; at most " + std::to_string(BodyStates::kMaxBodies) + " are supported");
  }
  for (BodyIndex b : c->bodies()) checkBody(b, kind + " '" + c->name() + "'");
  constraints_.push_back(std::move(c));
  return ConstraintIndex(numConstraints() - 1);
}

ForceIndex System::addForce(std::unique_ptr<Force> f) {
  requireBuildPhase("force");
  if (!f) throw InputError("addForce: null force");
  checkNewName(f->name(), "force");
  if (f->bodies().size() > static_cast<size_t>(BodyStates::kMaxBodies)) {
    throw InputError("force '" + f->name() + "': connects " + std::to_string(f->bodies().size()) +
                     " bodies; at most " + std::to_string(BodyStates::kMaxBodies) + " are supported");
  }
  for (BodyIndex b : f->bodies()) checkBody(b, "force '" + f->name() + "'");
  forces_.push_back(std::move(f));
  return ForceIndex(numForces() - 1);
}

void System::setGravity(const Vec3& g) {
  requireBuildPhase("gravity");
  for (int k = 0; k < 3; ++k) requireFinite(g[k], "gravity[" + std::to_string(k) + "]");
  gravity_ = g;
}

BodyIndex System::findBody(const std::string& name) const {
  for (int i = 0; i < numBodies(); ++i) {
    if (bodies_[i]->name() == name) return BodyIndex(i);
  }
  std::string known;
  for (const auto& b : bodies_) known += (known.empty() ? "" : ", ") + b->name();
  throw InputError("unknown body '" + name + "' (known bodies: " + known + ")");
}

ConstraintIndex System::findConstraint(const std::string& name) const {
  for (int i = 0; i < numConstraints(); ++i) {
    if (constraints_[i]->name() == name) return ConstraintIndex(i);
  }
  std::string known;
  for (const auto& c : constraints_) known += (known.empty() ? "" : ", ") + c->name();
  throw InputError("unknown joint '" + name + "' (known joints: " + (known.empty() ? "none" : known) + ")");
}

void System::finalize() {
  if (finalized_) {
    throw InputError("finalize: the system is already finalized (finalize() is called once, after everything is "
                     "added)");
  }
  // Attachment points resolved once into the bodies' identifiers (nodes of flexible
  // bodies): evaluations then find them without a search.
  auto resolve = [&](const std::vector<Attachment>& attachments, const std::string& user) {
    std::vector<int> ids;
    for (const auto& a : attachments) ids.push_back(body(a.body).resolvePoint(a.point, user));
    return ids;
  };
  constraintPointIds_.clear();
  forcePointIds_.clear();
  for (const auto& c : constraints_) {
    constraintPointIds_.push_back(resolve(c->attachments(), (c->isDriver() ? "driver '" : "joint '") + c->name() + "'"));
  }
  for (const auto& f : forces_) forcePointIds_.push_back(resolve(f->attachments(), "force '" + f->name() + "'"));
  bodyOffset_.clear();
  bodyVelocityOffset_.clear();
  bodyNq_.clear();
  bodyNv_.clear();
  nq_ = nv_ = 0;
  coordinateRates_ = true;
  for (const auto& b : bodies_) {
    bodyOffset_.push_back(nq_);
    bodyVelocityOffset_.push_back(nv_);
    bodyNq_.push_back(b->numCoordinates());
    bodyNv_.push_back(b->numVelocities());
    nq_ += b->numCoordinates();
    nv_ += b->numVelocities();
    coordinateRates_ = coordinateRates_ && b->velocitiesAreCoordinateRates();
  }
  // Coordinates used of each body: the union of the supports of the attachment points
  // on it (a joint on a node of a large flexible body uses only the frame and that
  // node's coordinates), all of them if nothing is attached there.
  auto usedCoordinates = [&](const std::vector<BodyIndex>& bs, const std::vector<Attachment>& attachments,
                             const std::vector<int>& ids,
                             const std::function<std::optional<std::vector<int>>(int)>& declared) {
    std::vector<std::vector<int>> used;
    for (size_t slot = 0; slot < bs.size(); ++slot) {
      if (auto d = declared(static_cast<int>(slot))) {
        used.push_back(*d);
        continue;
      }
      std::set<int> cols;
      bool attached = false;
      for (size_t k = 0; k < attachments.size(); ++k) {
        const BodyIndex b = attachments[k].body;
        if (b != bs[slot]) continue;
        attached = true;
        for (int c : body(b).pointSupport(attachments[k].point, ids[k])) cols.insert(c);
      }
      if (!attached) {
        for (int k = 0; k < body(bs[slot]).numVelocities(); ++k) cols.insert(k);
      }
      used.emplace_back(cols.begin(), cols.end());
    }
    return used;
  };
  auto coordinatesOf = [&](const std::vector<BodyIndex>& bs, const std::vector<std::vector<int>>& used) {
    std::vector<std::vector<int>> usedQ;
    for (size_t slot = 0; slot < bs.size(); ++slot) usedQ.push_back(body(bs[slot]).coordinatesOfVelocities(used[slot]));
    return usedQ;
  };
  auto globalColumns = [&](const std::vector<BodyIndex>& bs, const std::vector<std::vector<int>>& used,
                           const std::vector<int>& offsets) {
    std::vector<int> cols;
    for (size_t slot = 0; slot < bs.size(); ++slot) {
      for (int k : used[slot]) cols.push_back(offsets[bs[slot].value] + k);
    }
    return cols;
  };
  m_ = 0;
  constraintOffset_.clear();
  constraintCols_.clear();
  constraintQCols_.clear();
  constraintUsed_.clear();
  constraintUsedQ_.clear();
  constraintPeriod_.clear();
  constraintIsDriver_.clear();
  for (size_t ci = 0; ci < constraints_.size(); ++ci) {
    const auto& c = constraints_[ci];
    constraintPeriod_.push_back(c->equationPeriod());
    constraintIsDriver_.push_back(c->isDriver() ? 1 : 0);
    constraintOffset_.push_back(m_);
    m_ += c->numEquations();
    constraintUsed_.push_back(usedCoordinates(c->bodies(), c->attachments(), constraintPointIds_[ci], [&](int slot) { return c->coordinatesUsed(slot); }));
    constraintUsedQ_.push_back(coordinatesOf(c->bodies(), constraintUsed_.back()));
    constraintCols_.push_back(globalColumns(c->bodies(), constraintUsed_.back(), bodyVelocityOffset_));
    constraintQCols_.push_back(globalColumns(c->bodies(), constraintUsedQ_.back(), bodyOffset_));
  }
  forceCols_.clear();
  forceQCols_.clear();
  forceUsed_.clear();
  forceUsedQ_.clear();
  for (size_t fi = 0; fi < forces_.size(); ++fi) {
    const auto& f = forces_[fi];
    forceUsed_.push_back(usedCoordinates(f->bodies(), f->attachments(), forcePointIds_[fi], [](int) { return std::nullopt; }));
    forceUsedQ_.push_back(coordinatesOf(f->bodies(), forceUsed_.back()));
    forceCols_.push_back(globalColumns(f->bodies(), forceUsed_.back(), bodyVelocityOffset_));
    forceQCols_.push_back(globalColumns(f->bodies(), forceUsedQ_.back(), bodyOffset_));
  }
  checkInertiaSpread();
  finalized_ = true;
}

void System::checkInertiaSpread() const {
  std::vector<NamedMagnitude> masses, inertias;
  for (size_t b = 1; b < bodies_.size(); ++b) {  // 0 is the ground
    const Body& body = *bodies_[b];
    const std::string owner = "body '" + body.name() + "'";
    masses.push_back({owner, body.mass()});
    // rotational inertias of the rigid frames: the angle rows of the mass matrix's diagonal
    // (a flexible body's full matrix is not formed here)
    if (body.numVelocities() != body.numFrameVelocities()) continue;
    const MatX M = body.massMatrix(body.initialCoordinates());
    const std::vector<CoordinateKind> kinds = body.velocityKinds();
    const std::vector<std::string> names = body.velocityNames();
    for (int k = 0; k < body.numVelocities(); ++k) {
      if (kinds[k] == CoordinateKind::Angle) inertias.push_back({owner + " (" + names[k] + ")", M(k, k)});
    }
  }
  checkMagnitudeSpread("mass", masses);
  checkMagnitudeSpread("rotational inertia", inertias);
}

VecX System::initialCoordinates() const {
  requireFinalized("initialCoordinates");
  VecX q(nq_);
  for (int i = 0; i < numBodies(); ++i) {
    q.segment(bodyOffset_[i], bodies_[i]->numCoordinates()) = bodies_[i]->initialCoordinates();
  }
  return q;
}

VecX System::initialVelocities() const {
  requireFinalized("initialVelocities");
  VecX v(nv_);
  for (int i = 0; i < numBodies(); ++i) {
    v.segment(bodyVelocityOffset_[i], bodies_[i]->numVelocities()) = bodies_[i]->initialVelocities();
  }
  return v;
}

VecX System::applyIncrement(const VecX& q, const VecX& dv) const {
  requireFinalized("applyIncrement");
  if (coordinateRates_) return q + dv;
  VecX out(nq_);
  for (int i = 0; i < numBodies(); ++i) {
    const int nq = bodies_[i]->numCoordinates(), nv = bodies_[i]->numVelocities();
    bodies_[i]->applyIncrement(q.segment(bodyOffset_[i], nq), dv.segment(bodyVelocityOffset_[i], nv),
                               out.segment(bodyOffset_[i], nq));
  }
  return out;
}

VecX System::coordinateRates(const VecX& q, const VecX& v) const {
  requireFinalized("coordinateRates");
  if (coordinateRates_) return v;
  VecX out = VecX::Zero(nq_);
  for (int i = 0; i < numBodies(); ++i) {
    const int nq = bodies_[i]->numCoordinates(), nv = bodies_[i]->numVelocities();
    bodies_[i]->addCoordinateRate(q.segment(bodyOffset_[i], nq), v.segment(bodyVelocityOffset_[i], nv),
                                  out.segment(bodyOffset_[i], nq));
  }
  return out;
}

BodyStates System::states(const std::vector<BodyIndex>& bs, const std::vector<std::vector<int>>& used,
                          const std::vector<std::vector<int>>& usedQ, const double* q) const {
  BodyStates out;
  // indices valid after finalize (the callers' checks): no bounds checks, no virtual calls
  for (size_t slot = 0; slot < bs.size(); ++slot) {
    const int b = bs[slot].value;
    out.add(*bodies_[b], q + bodyOffset_[b], bodyNq_[b], &used[slot], &usedQ[slot]);
  }
  return out;
}

BodyStates System::constraintStates(ConstraintIndex i, const double* q) const {
  if (static_cast<size_t>(i.value) >= constraintUsed_.size()) requireFinalized("constraintStates");
  BodyStates out =
      states(constraints_.at(i.value)->bodies(), constraintUsed_[i.value], constraintUsedQ_[i.value], q);
  const std::vector<int>& ids = constraintPointIds_[i.value];
  out.setPointIds(ids.data(), static_cast<int>(ids.size()));
  return out;
}

BodyStates System::forceStates(ForceIndex i, const double* q) const {
  if (static_cast<size_t>(i.value) >= forceUsed_.size()) requireFinalized("forceStates");
  BodyStates out = states(forces_.at(i.value)->bodies(), forceUsed_[i.value], forceUsedQ_[i.value], q);
  const std::vector<int>& ids = forcePointIds_[i.value];
  out.setPointIds(ids.data(), static_cast<int>(ids.size()));
  return out;
}

std::string System::describeEquation(int row) const {
  for (int c = numConstraints() - 1; c >= 0; --c) {
    const ConstraintIndex ci(c);
    if (row >= constraintOffset(ci)) {
      const Constraint& con = constraint(ci);
      return std::string(con.isDriver() ? "driver '" : "joint '") + con.name() + "' (" + con.typeName() +
             ", equation " + std::to_string(row - constraintOffset(ci)) + ")";
    }
  }
  return "?";
}

std::vector<int> System::frameCoordinates() const {
  requireFinalized("frameCoordinates");
  std::vector<int> idx;
  for (int b = 0; b < numBodies(); ++b) {
    for (int k = 0; k < bodies_[b]->numFrameCoordinates(); ++k) idx.push_back(bodyOffset_[b] + k);
  }
  return idx;
}

std::vector<int> System::frameVelocities() const {
  requireFinalized("frameVelocities");
  std::vector<int> idx;
  for (int b = 0; b < numBodies(); ++b) {
    for (int k = 0; k < bodies_[b]->numFrameVelocities(); ++k) idx.push_back(bodyVelocityOffset_[b] + k);
  }
  return idx;
}

std::vector<CoordinateKind> System::coordinateKinds() const {
  std::vector<CoordinateKind> kinds;
  for (const auto& b : bodies_) {
    for (CoordinateKind k : b->coordinateKinds()) kinds.push_back(k);
  }
  return kinds;
}

std::vector<CoordinateKind> System::velocityKinds() const {
  std::vector<CoordinateKind> kinds;
  for (const auto& b : bodies_) {
    for (CoordinateKind k : b->velocityKinds()) kinds.push_back(k);
  }
  return kinds;
}

double System::characteristicLength() const {
  double L = 0.0;
  for (const auto& b : bodies_) {
    const VecX q = b->initialCoordinates();
    const auto kinds = b->coordinateKinds();
    double r2 = 0.0;
    for (int k = 0; k < q.size(); ++k) r2 += kinds[k] == CoordinateKind::Position ? q[k] * q[k] : 0.0;
    L = std::max(L, std::sqrt(r2));
  }
  for (const auto& c : constraints_) {
    for (const auto& [b, p] : c->attachments()) L = std::max(L, p.norm());
  }
  for (const auto& f : forces_) {
    for (const auto& [b, p] : f->attachments()) L = std::max(L, p.norm());
  }
  return L > 0.0 ? L : 1.0;
}

std::vector<std::string> System::coordinateNames() const {
  std::vector<std::string> names;
  for (const auto& b : bodies_) {
    for (const auto& c : b->coordinateNames()) names.push_back(b->name() + "." + c);
  }
  return names;
}

std::vector<std::string> System::accelerationNames() const {
  std::vector<std::string> names = velocityNames();
  const std::string dot = "_dot";
  for (auto& n : names) {
    const bool rate = n.size() > dot.size() && n.compare(n.size() - dot.size(), dot.size(), dot) == 0;
    n = rate ? n.substr(0, n.size() - dot.size()) + "_ddot" : n + "_dot";
  }
  return names;
}

std::vector<std::string> System::velocityNames() const {
  std::vector<std::string> names;
  for (const auto& b : bodies_) {
    for (const auto& c : b->velocityNames()) names.push_back(b->name() + "." + c);
  }
  return names;
}

}  // namespace flexmbd
