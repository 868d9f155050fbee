#include "tensegrity/tensegrity_time_stepper.hpp"
#include "simulation/simulation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <optional>
#include <sstream>

#include "core/errors.hpp"
#include "core/stop_request.hpp"
#include "tensegrity/member_contact_detector.hpp"
#include "tensegrity/segment_closest_points.hpp"

namespace flexmbd {

/// Largest relative energy increase over a step with a snap (an inelastic impulse, which
/// dissipates), beyond the work of the loads over the step: the LCP and the projection
/// leave round-off of 1e-12 (tests/test_tensegrity_snap.cpp); 1e-6 is far above it and far
/// below energy created from an overflowing 1/m (100 %).
constexpr double kMaxSnapEnergyGrowth = 1e-6;

std::vector<std::string> tensegrityColumns(const TensegrityStructure& s) {
  const char* axes[3] = {"x", "y", "z"};
  std::vector<std::string> c = {"t"};
  for (int i = 0; i < s.numNodes(); ++i) {
    for (int a = 0; a < s.dimension(); ++a) c.push_back(s.node(i).name + "." + axes[a]);
  }
  for (int i = 0; i < s.numNodes(); ++i) {
    for (int a = 0; a < s.dimension(); ++a) c.push_back(s.node(i).name + ".v" + axes[a]);
  }
  for (int i = 0; i < s.numStruts(); ++i) {
    c.push_back(s.strut(i).name + ".force");
    c.push_back(s.strut(i).name + ".length");
  }
  for (int k = 0; k < s.numCables(); ++k) {
    for (const char* e : {".tension", ".slack", ".impulse", ".length"}) c.push_back(s.cable(k).name + e);
  }
  c.insert(c.end(), {"energy.kinetic", "energy.potential", "energy.total"});
  return c;
}

void tensegrityRow(const TensegrityStructure& s, const TensegritySample& smp, std::vector<double>& values) {
  // A row with a non-finite value is not written: the run stops there.
  const auto check = [&](bool finite, const std::string& what) {
    if (!finite) {
      std::ostringstream t;
      t.precision(17);
      t << smp.t;
      throw NonFiniteResult("non-finite " + what + " at t = " + t.str());
    }
  };
  check(std::isfinite(smp.t), "time");
  check(smp.x.allFinite(), "node positions");
  check(smp.v.allFinite(), "node velocities");
  for (int c = 0; c < s.numCables(); ++c) {
    check(std::isfinite(smp.cableTension[c]) && std::isfinite(smp.cableImpulse[c]) && std::isfinite(smp.cableLength[c]),
          "tension, impulse or length of cable \"" + s.cable(c).name + "\"");
  }
  check(std::isfinite(smp.kineticEnergy) && std::isfinite(smp.potentialEnergy) &&
            std::isfinite(smp.kineticEnergy + smp.potentialEnergy),
        "energy");
  values.clear();
  values.push_back(smp.t);
  values.insert(values.end(), smp.x.data(), smp.x.data() + smp.x.size());
  values.insert(values.end(), smp.v.data(), smp.v.data() + smp.v.size());
  for (int i = 0; i < s.numStruts(); ++i) {
    // N = EA (l - l0) / l0, tension positive (TensegrityStructure::strutForce; Doc001)
    const double force = s.strutForce(smp.x, i), length = s.strutLength(smp.x, i);
    check(std::isfinite(force) && std::isfinite(length), "force or length of strut \"" + s.strut(i).name + "\"");
    values.insert(values.end(), {force, length});
  }
  for (int c = 0; c < s.numCables(); ++c) {
    values.insert(values.end(),
                  {smp.cableTension[c], smp.slack[c] ? 1.0 : 0.0, smp.cableImpulse[c], smp.cableLength[c]});
  }
  values.insert(values.end(), {smp.kineticEnergy, smp.potentialEnergy, smp.kineticEnergy + smp.potentialEnergy});
}

std::string toString(TensegrityEvent::Type type) {
  switch (type) {
    case TensegrityEvent::Type::Snap: return "snap";
    case TensegrityEvent::Type::Taut: return "taut";
    case TensegrityEvent::Type::Slack: return "slack";
    case TensegrityEvent::Type::Contact: return "contact";
  }
  return "?";
}

namespace {

using Row = std::vector<std::pair<int, double>>;

/// W = B Minv B^T for sparse rows B (each at most 6 entries; Doc001, method 1).
MatX delassus(const std::vector<Row>& B, const MatX& Minv) {
  const int n = static_cast<int>(B.size());
  MatX W(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = a; b < n; ++b) {
      double w = 0.0;
      for (const auto& [k, bk] : B[a]) {
        for (const auto& [l, bl] : B[b]) w += bk * Minv(k, l) * bl;
      }
      W(a, b) = W(b, a) = w;
    }
  }
  return W;
}

/// Minv B^T p.
VecX impulseResponse(const std::vector<Row>& B, const VecX& p, const MatX& Minv) {
  VecX r = VecX::Zero(Minv.rows());
  for (std::size_t a = 0; a < B.size(); ++a) {
    if (p[a] == 0.0) continue;
    for (const auto& [k, bk] : B[a]) r += Minv.col(k) * (bk * p[a]);
  }
  return r;
}

double rowDot(const Row& b, const VecX& v) {
  double s = 0.0;
  for (const auto& [k, bk] : b) s += bk * v[k];
  return s;
}

/// A pair of members that may touch (contact constraints): node indices, r_a + r_b and
/// the length scale L of the relative penetration (mean initial length of the two).
struct ContactPair {
  int ai, aj, bi, bj;
  double reach, scale;
};

struct ContactRow {
  double gap = 0.0;  ///< d - (r_a + r_b)
  Row b;             ///< -d gap/du on the free coordinates (the cables' sign: w = -b v)
};

/// Gap and its gradient at x, closest points frozen (their derivative does not enter:
/// d is stationary in the segment parameters, or they sit at a clamped end).
ContactRow contactRow(const TensegrityStructure& s, const VecX& x, const ContactPair& p) {
  const int dim = s.dimension();
  auto pt = [&](int n) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    r.head(dim) = x.segment(dim * n, dim);
    return r;
  };
  const Eigen::Vector3d a0 = pt(p.ai), a1 = pt(p.aj), b0 = pt(p.bi), b1 = pt(p.bj);
  const SegmentClosestPoints cp = closestPointsOfSegments(a0, a1, b0, b1);
  Eigen::Vector3d n = cp.c1 - cp.c2;  // from member b to member a
  if (cp.distance > 1e-14 * p.scale) {
    n /= cp.distance;
  } else {  // axes intersect: the normal of the two axes (undefined if parallel)
    n = (a1 - a0).cross(b1 - b0);
    if (dim == 2 || n.norm() <= 1e-14 * p.scale * p.scale) {
      throw SolverError("contact constraint: the axes of two members intersect, the contact normal is undefined", 0.0,
                        0.0);
    }
    n.normalize();
  }
  ContactRow out;
  out.gap = cp.distance - p.reach;
  const double w[4] = {1.0 - cp.s, cp.s, -(1.0 - cp.t), -cp.t};
  const int nodes[4] = {p.ai, p.aj, p.bi, p.bj};
  for (int k = 0; k < 4; ++k) {
    for (int c = 0; c < dim; ++c) {
      const int f = s.freeIndexOf(dim * nodes[k] + c);
      if (f >= 0 && w[k] * n[c] != 0.0) out.b.emplace_back(f, -w[k] * n[c]);
    }
  }
  return out;
}

std::string num(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

}  // namespace

std::optional<std::string> snapEnergyGrowth(double energyBefore, double energyAfter, double loadWork) {
  const double growth = energyAfter - energyBefore - loadWork;
  if (!(growth > kMaxSnapEnergyGrowth * std::max(std::fabs(energyBefore), std::fabs(energyAfter)))) {
    return std::nullopt;
  }
  return "the energy grew at a snap: from " + num(energyBefore) + " to " + num(energyAfter) + " J with " +
         num(loadWork) + " J of work by the loads (a snap dissipates; more than " + num(kMaxSnapEnergyGrowth) +
         " relative growth is not physical: check tiny node masses beside the cables' impulses)";
}

TensegrityTimeStepper::TensegrityTimeStepper(const TensegrityStructure& structure,
                                             const TimeSteppingSettings& settings)
    : s_(structure), settings_(settings) {
  const TimeSteppingSettings& o = settings_;
  if (!s_.finalized()) throw InputError("time stepping: the tensegrity structure is not finalized");
  if (!(o.timeStep > 0.0) || !std::isfinite(o.timeStep)) {
    throw InputError("solver.time_step must be > 0, got " + num(o.timeStep));
  }
  if (!(o.tEnd > o.tStart)) throw InputError("solver.t_end must be > t_start, got " + num(o.tEnd));
  if (!(o.outputStep >= 0.0)) throw InputError("solver.output_step must be >= 0, got " + num(o.outputStep));
  // Bounded work (a run never hangs): t_end 1e100 with time_step 1e-3 is 1e103 steps.
  constexpr double kMaxSteps = 1e9;
  if (!((o.tEnd - o.tStart) / o.timeStep <= kMaxSteps)) {
    throw InputError("solver.t_end: at most 1e9 time steps of " + num(o.timeStep) + " s expected, got (t_end - t_start) / "
                     "time_step = " + num((o.tEnd - o.tStart) / o.timeStep));
  }
  if (!(o.outputStep / o.timeStep <= kMaxSteps)) {
    throw InputError("solver.output_step: at most 1e9 time steps per output expected, got " + num(o.outputStep));
  }
  if (!(o.projectionTolerance > 0.0)) throw InputError("solver.projection_tolerance must be > 0");
  if (!(o.slackTolerance >= 0.0)) throw InputError("solver.slack_tolerance must be >= 0");
  if (o.maxProjectionIterations < 1) throw InputError("solver.max_projection_iterations must be >= 1");
  LcpSolver check(o.lcp);  // validates the LCP options
}

namespace {

/// The pairs of members that may touch (contact constraints): every two members sharing
/// no node, with r_a + r_b and the mean of their initial lengths.
std::vector<ContactPair> memberContactPairs(const TensegrityStructure& s) {
  std::vector<ContactPair> cpairs;
  const std::vector<MemberRef> mem = s.members();
  const VecX x0 = s.initialPositions();
  auto length = [&](int i, int j) {
    return (x0.segment(s.dimension() * j, s.dimension()) - x0.segment(s.dimension() * i, s.dimension())).norm();
  };
  for (std::size_t a = 0; a < mem.size(); ++a) {
    for (std::size_t b = a + 1; b < mem.size(); ++b) {
      const auto [ai, aj] = s.memberNodes(mem[a]);
      const auto [bi, bj] = s.memberNodes(mem[b]);
      if (ai == bi || ai == bj || aj == bi || aj == bj) continue;
      cpairs.push_back({ai, aj, bi, bj, s.memberRadius(mem[a]) + s.memberRadius(mem[b]),
                        0.5 * (length(ai, aj) + length(bi, bj))});
    }
  }
  return cpairs;
}

/// M^-1 on the free coordinates (the mass matrix is constant).
MatX inverseMassMatrix(const TensegrityStructure& s) {
  const int nf = s.numFreeCoordinates();
  return s.massMatrix().ldlt().solve(MatX::Identity(nf, nf));
}

/// The number of steps over [tStart, tEnd]; the last one is shortened to end at tEnd.
long numberOfSteps(const TimeSteppingSettings& o) {
  const double span = o.tEnd - o.tStart;
  return std::max(1L, static_cast<long>(std::ceil(span / o.timeStep - 1e-9)));
}

/// One run of TensegrityTimeStepper: the state carried from step to step (positions,
/// velocities, time, the cables' slack and carrying flags, the impulses the samples
/// report, the summary, the contact detector) and the stages of a step.
class TimeSteppingRun {
 public:
  /// The initial state: positions, velocities, slack cables, the summary's start.
  TimeSteppingRun(const TensegrityStructure& s, const TimeSteppingSettings& o, const TensegrityObserver& observer);

  /// The first contact events and sample, then the steps. A SolverError ends the run
  /// with ok = false; the summary has everything but cpuSeconds.
  TensegrityRunSummary run();

 private:
  /// The velocity and impulses of one step (the LCP at the midpoint).
  struct StepImpulses {
    VecX vf;                  ///< v_f on the free coordinates, after the impulses
    std::vector<int> active;  ///< the inextensible cables in the LCP
    std::vector<Row> B;       ///< the rows of the active cables, then of the touching contact pairs
    VecX p;                   ///< the impulses, one per row of B
  };

  double energy(const VecX& xx, const VecX& vv) const { return s_.kineticEnergy(vv) + s_.potentialEnergy(xx); }
  /// Counts the event in the summary and hands it to the observer.
  void emit(TensegrityEvent e);
  /// The contact detector (option) and the contacts of the initial positions.
  void startContactDetection();
  /// The sample written to the observer (the snap impulses are summed until it).
  void sample();
  /// One time step from t_ over dt (the last one shortened to end at tEnd).
  void takeStep(long step);
  /// Midpoint, free velocity, active set and the LCP of the impulses.
  StepImpulses stepImpulses(long step, double dt, double tm, const VecX& xm, const VecX& vFreeI);
  /// Largest relative drift of the inextensible cables and penetration of the contact pairs.
  double drift(const VecX& xx) const;
  /// The projection of the drift at u_f (option) and its bookkeeping.
  void projectPositions(long step, double dt, VecX& xf);
  /// x, v and the impulses of the step taken; its snap, taut and slack events; the energy
  /// check of a snap; the contact events; the time advanced.
  void commitStep(long step, double dt, double tm, const VecX& xi, double Ei, const VecX& vFreeI, const VecX& xf,
                  const StepImpulses& imp);
  /// The contact events between (t_, xi) and (tf, x_), in time order.
  void emitContactEvents(long step, double tf, const VecX& xi);

  const TensegrityStructure& s_;
  const TimeSteppingSettings& o_;
  const TensegrityObserver& observer_;
  const LcpSolver lcp_;
  const int nc_;
  const MatX Minv_;
  const std::vector<ContactPair> cpairs_;
  const long nSteps_;
  const long outEvery_;
  TensegrityRunSummary sum_;
  VecX x_, v_;
  double t_;
  std::vector<bool> slack_, carried_;
  VecX lastImpulse_, snapImpulse_;
  double lastDt_;
  std::optional<MemberContactDetector> contacts_;
  std::vector<TensegrityEvent> pending_;
  long stepsTaken_ = 0;
};

TimeSteppingRun::TimeSteppingRun(const TensegrityStructure& s, const TimeSteppingSettings& o,
                                 const TensegrityObserver& observer)
    : s_(s),
      o_(o),
      observer_(observer),
      lcp_(o.lcp),
      nc_(s.numCables()),
      Minv_(inverseMassMatrix(s)),
      cpairs_(o.contactConstraints ? memberContactPairs(s) : std::vector<ContactPair>()),
      nSteps_(numberOfSteps(o)),
      outEvery_(o.outputStep > 0.0 ? std::max(1L, std::lround(o.outputStep / o.timeStep)) : 1L),
      x_(s.initialPositions()),
      v_(s.initialVelocities()),
      t_(o.tStart),
      slack_(nc_, false),
      carried_(nc_, false),
      lastImpulse_(VecX::Zero(nc_)),
      snapImpulse_(VecX::Zero(nc_)),
      lastDt_(o.timeStep) {
  sum_.method = "time_stepping";
  sum_.lcpSolver = toString(o_.lcp.method);
  sum_.energyStart = energy(x_, v_);
  const VecX l = s_.cableLengths(x_);
  for (int c = 0; c < nc_; ++c) slack_[c] = l[c] < s_.cable(c).naturalLength * (1.0 - o_.slackTolerance);
}

void TimeSteppingRun::emit(TensegrityEvent e) {
  sum_.count(e);
  if (observer_.onEvent) observer_.onEvent(e);
}

void TimeSteppingRun::startContactDetection() {
  if (o_.detectContacts) {
    contacts_.emplace(s_);
    contacts_->start(t_, x_, pending_);
    for (auto& e : pending_) emit(e);
    pending_.clear();
  }
}

void TimeSteppingRun::sample() {
  if (!observer_.onSample) return;
  TensegritySample smp;
  smp.t = t_;
  smp.steps = stepsTaken_;
  smp.x = x_;
  smp.v = v_;
  smp.cableLength = s_.cableLengths(x_);
  smp.cableTension = s_.elasticCableTensions(x_);
  for (int c = 0; c < nc_; ++c) {
    if (s_.cable(c).inextensible) smp.cableTension[c] = lastImpulse_[c] / lastDt_;
  }
  smp.cableImpulse = snapImpulse_;
  smp.slack = slack_;
  smp.kineticEnergy = s_.kineticEnergy(v_);
  smp.potentialEnergy = s_.potentialEnergy(x_);
  observer_.onSample(smp);
  snapImpulse_.setZero();
}

TensegrityRunSummary TimeSteppingRun::run() {
  startContactDetection();
  sample();
  try {
    for (long step = 1; step <= nSteps_; ++step) takeStep(step);
    sum_.ok = true;
    sum_.message = "ok";
  } catch (const SolverError& e) {
    sum_.ok = false;
    sum_.message = e.what();
    sum_.tReached = t_;
  }
  sum_.energyEnd = energy(x_, v_);
  return sum_;
}

void TimeSteppingRun::takeStep(long step) {
  pollStop(t_);  // core/stop_request.hpp
  const double dt = step == nSteps_ ? o_.tEnd - t_ : o_.timeStep;
  const double tm = t_ + 0.5 * dt;
  const VecX xi = x_, vi = v_;
  const double Ei = energy(xi, vi);
  const VecX vFreeI = s_.restrict(vi);
  // Midpoint u_m = u_i + v_i dt/2 (Doc001, sec. 3.2).
  const VecX xm = xi + 0.5 * dt * vi;
  const StepImpulses imp = stepImpulses(step, dt, tm, xm, vFreeI);
  VecX xf = xm + 0.5 * dt * s_.expand(imp.vf, VecX::Zero(s_.numCoordinates()));
  projectPositions(step, dt, xf);
  commitStep(step, dt, tm, xi, Ei, vFreeI, xf, imp);
  if (step % outEvery_ == 0 || step == nSteps_) sample();
}

TimeSteppingRun::StepImpulses TimeSteppingRun::stepImpulses(long step, double dt, double tm, const VecX& xm,
                                                            const VecX& vFreeI) {
  // v_free = v_i + M^-1 (f(t_m) - g(u_m)) dt (Doc001, method 1)
  const VecX force = s_.restrict(s_.externalForces(tm) - s_.internalForces(xm));
  VecX vf = vFreeI + Minv_ * (force * dt);
  // Active set: inextensible cables at or beyond their natural length at u_m.
  const VecX lm = s_.cableLengths(xm);
  std::vector<int> active;
  std::vector<Row> B;
  for (int c = 0; c < nc_; ++c) {
    const TensegrityCable& cb = s_.cable(c);
    if (!cb.inextensible) continue;
    if (lm[c] >= cb.naturalLength * (1.0 - o_.slackTolerance)) {
      active.push_back(c);
      B.push_back(s_.cableGradientEntries(xm, c));
    }
  }
  // Contact constraints (option): rows after the cables' ones.
  for (const ContactPair& cp : cpairs_) {
    ContactRow r = contactRow(s_, xm, cp);
    if (r.gap <= o_.slackTolerance * cp.scale) B.push_back(std::move(r.b));
  }
  VecX p = VecX::Zero(static_cast<int>(B.size()));
  if (!B.empty()) {
    const MatX W = delassus(B, Minv_);
    VecX q(static_cast<int>(B.size()));
    for (std::size_t a = 0; a < B.size(); ++a) q[a] = -rowDot(B[a], vf);
    const LcpSolution sol = lcp_.solve(W, q);
    sum_.maxLcpResidual = std::max(sum_.maxLcpResidual, sol.residual);
    sum_.maxLcpSize = std::max(sum_.maxLcpSize, static_cast<int>(active.size()));
    sum_.lcpIterations += sol.iterations;
    ++sum_.lcpSolves;
    sum_.lcpSizeSum += static_cast<long>(B.size());
    if (!sol.ok) {
      throw SolverError("LCP (" + toString(o_.lcp.method) + ") of the cable impulses failed at step " +
                            std::to_string(step) + " (t = " + num(t_) + ", dt = " + num(dt) + ", " +
                            std::to_string(active.size()) + " active cables, " +
                            std::to_string(B.size() - active.size()) + " contacts): residual " + num(sol.residual) +
                            " > tolerance " + num(o_.lcp.tolerance) + " after " + std::to_string(sol.iterations) +
                            " iterations (Siconos info " + std::to_string(sol.info) + ")",
                        t_, dt);
    }
    p = sol.z;
    for (std::size_t a = active.size(); a < B.size(); ++a) sum_.contactImpulseSum += p[a];
    vf -= impulseResponse(B, p, Minv_);
  }
  return {std::move(vf), std::move(active), std::move(B), std::move(p)};
}

double TimeSteppingRun::drift(const VecX& xx) const {
  const VecX l = s_.cableLengths(xx);
  double d = 0.0;
  for (int c = 0; c < nc_; ++c) {
    if (s_.cable(c).inextensible) d = std::max(d, (l[c] - s_.cable(c).naturalLength) / s_.cable(c).naturalLength);
  }
  for (const ContactPair& cp : cpairs_) d = std::max(d, -contactRow(s_, xx, cp).gap / cp.scale);
  return d;
}

void TimeSteppingRun::projectPositions(long step, double dt, VecX& xf) {
  // Drift of inextensible cables and its projection.
  double d = drift(xf);
  sum_.maxDriftBeforeProjection = std::max(sum_.maxDriftBeforeProjection, d);
  if (o_.projectPositions) {
    for (int it = 0; it < o_.maxProjectionIterations && d > o_.projectionTolerance; ++it) {
      ++sum_.projectionIterations;
      const VecX l = s_.cableLengths(xf);
      std::vector<Row> Bp;
      VecX g;
      std::vector<double> gs;
      for (int c = 0; c < nc_; ++c) {
        const TensegrityCable& cb = s_.cable(c);
        if (cb.inextensible && l[c] >= cb.naturalLength * (1.0 - o_.slackTolerance)) {
          Bp.push_back(s_.cableGradientEntries(xf, c));
          gs.push_back(l[c] - cb.naturalLength);
        }
      }
      for (const ContactPair& cp : cpairs_) {
        ContactRow r = contactRow(s_, xf, cp);
        if (r.gap <= o_.slackTolerance * cp.scale) {
          Bp.push_back(std::move(r.b));
          gs.push_back(-r.gap);
        }
      }
      g = Eigen::Map<const VecX>(gs.data(), static_cast<int>(gs.size()));
      const LcpSolution sol = lcp_.solve(delassus(Bp, Minv_), -g);
      if (!sol.ok) {
        throw SolverError("LCP (" + toString(o_.lcp.method) + ") of the position projection failed at step " +
                              std::to_string(step) + " (t = " + num(t_) + "): residual " + num(sol.residual) +
                              " > tolerance " + num(o_.lcp.tolerance),
                          t_, dt);
      }
      xf -= s_.expand(impulseResponse(Bp, sol.z, Minv_), VecX::Zero(s_.numCoordinates()));
      d = drift(xf);
    }
    sum_.maxDriftAfterProjection = std::max(sum_.maxDriftAfterProjection, d);
  } else {
    sum_.maxDriftAfterProjection = sum_.maxDriftBeforeProjection;
  }
}

void TimeSteppingRun::commitStep(long step, double dt, double tm, const VecX& xi, double Ei, const VecX& vFreeI,
                                 const VecX& xf, const StepImpulses& imp) {
  // Commit the step.
  const double tf = t_ + dt;
  x_ = xf;
  v_ = s_.expand(imp.vf, VecX::Zero(s_.numCoordinates()));
  const double Ef = energy(x_, v_);
  lastImpulse_.setZero();
  for (std::size_t a = 0; a < imp.active.size(); ++a) lastImpulse_[imp.active[a]] = imp.p[a];
  // Events: snaps (impulse on a cable that was not carrying tension and was
  // lengthening), taut and slack transitions. Times: where the gap l - l0 crosses
  // zero, interpolated linearly between u_i and u_f.
  const VecX li = s_.cableLengths(xi), lf = s_.cableLengths(x_);
  bool snapped = false;
  for (int c = 0; c < nc_; ++c) {
    const double l0 = s_.cable(c).naturalLength;
    const bool nowSlack = lf[c] < l0 * (1.0 - o_.slackTolerance);
    const double gi = li[c] - l0, gf = lf[c] - l0;
    const double crossing = (gi < 0.0 && gf >= 0.0) || (gi >= 0.0 && gf < 0.0) ? t_ + dt * gi / (gi - gf) : tm;
    const double pc = lastImpulse_[c];
    double rate = 0.0;
    if (pc > 0.0) {
      const auto ai = std::find(imp.active.begin(), imp.active.end(), c) - imp.active.begin();
      rate = rowDot(imp.B[ai], vFreeI);
    }
    TensegrityEvent e;
    e.step = step;
    e.member = s_.cable(c).name;
    if (pc > 0.0 && !carried_[c] && rate > o_.snapRateTolerance) {
      e.type = TensegrityEvent::Type::Snap;
      e.t = std::clamp(crossing, t_, tf);
      e.impulse = pc;
      e.elongationRate = rate;
      e.energyChange = Ef - Ei;
      snapImpulse_[c] += pc;
      snapped = true;
      emit(e);
    } else if (slack_[c] && !nowSlack) {
      e.type = TensegrityEvent::Type::Taut;
      e.t = std::clamp(crossing, t_, tf);
      emit(e);
    }
    if (!slack_[c] && nowSlack) {
      e.type = TensegrityEvent::Type::Slack;
      e.t = std::clamp(crossing, t_, tf);
      e.impulse = 0.0;
      emit(e);
    }
    slack_[c] = nowSlack;
    carried_[c] = pc > 0.0;
  }
  if (snapped) sum_.maxEnergyIncreaseAtSnap = std::max(sum_.maxEnergyIncreaseAtSnap, Ef - Ei);
  if (snapped) {
    // the loads' work over the step at the force the step applied (midpoint time tm)
    const double loadWork = s_.loadForces(tm).dot(x_ - xi);
    if (const std::optional<std::string> grown = snapEnergyGrowth(Ei, Ef, loadWork)) {
      throw SolverError("between t = " + num(t_) + " and t = " + num(tf) + ": " + *grown, t_, dt);
    }
  }
  if (contacts_) emitContactEvents(step, tf, xi);
  t_ = tf;
  lastDt_ = dt;
  sum_.steps = step;
  sum_.tReached = t_;
  stepsTaken_ = step;
}

void TimeSteppingRun::emitContactEvents(long step, double tf, const VecX& xi) {
  contacts_->advance(t_, xi, tf, x_, pending_);
  std::sort(pending_.begin(), pending_.end(),
            [](const TensegrityEvent& a, const TensegrityEvent& b) { return a.t < b.t; });
  for (auto& e : pending_) {
    e.step = step;
    emit(e);
  }
  pending_.clear();
}

}  // namespace

TensegrityRunSummary TensegrityTimeStepper::run(const TensegrityObserver& observer) const {
  const std::clock_t cpuStart = std::clock();
  TensegrityRunSummary sum = TimeSteppingRun(s_, settings_, observer).run();
  sum.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  return sum;
}

}  // namespace flexmbd
