#include "tensegrity/massless_cable_integrator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <optional>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "tensegrity/member_contact_detector.hpp"

namespace flexmbd {

namespace {

/// Figures in messages: six significant digits (core/number_text.hpp).
std::string num(double x) { return fmt(x, 6); }

/// y = [u_free, v_free]; y' = [v_free, M^-1 (f - g)] (Doc001, method 2).
class TensegrityOde : public OdeSystem {
 public:
  explicit TensegrityOde(const TensegrityStructure& s)
      : s_(s), nf_(s.numFreeCoordinates()), ldlt_(s.massMatrix()), x0_(s.initialPositions()) {}

  int size() const override { return 2 * nf_; }
  int numRoots() const override { return s_.numCables(); }

  VecX fullPositions(const double* y) const { return s_.expand(Eigen::Map<const VecX>(y, nf_), x0_); }
  VecX fullVelocities(const double* y) const {
    return s_.expand(Eigen::Map<const VecX>(y + nf_, nf_), VecX::Zero(s_.numCoordinates()));
  }

  void rhs(double t, const double* y, double* ydot) const override {
    const VecX x = fullPositions(y);
    // internalForces includes the struts and the elastic cables' tension-only law.
    const VecX f = s_.restrict(s_.externalForces(t) - s_.internalForces(x));
    Eigen::Map<VecX>(ydot, nf_) = Eigen::Map<const VecX>(y + nf_, nf_);
    Eigen::Map<VecX>(ydot + nf_, nf_) = ldlt_.solve(f);
  }

  /// g_c = (l_c - l0_c)/l0_c: positive when taut, negative when slack.
  void roots(double, const double* y, double* g) const override {
    const VecX l = s_.cableLengths(fullPositions(y));
    for (int c = 0; c < s_.numCables(); ++c) g[c] = (l[c] - s_.cable(c).naturalLength) / s_.cable(c).naturalLength;
  }

 private:
  const TensegrityStructure& s_;
  int nf_;
  Eigen::LDLT<MatX> ldlt_;
  VecX x0_;
};

/// Most cable switches (taut or slack roots, each a restart of CVODE) within one output
/// interval: a cable goes taut and slack about once per period of its node's oscillation,
/// which the output step resolves; 10,000 in one interval is an event storm whose switching
/// times converge (a 1e-300 node mass: a root every 1,700 steps, no progress in 15 CPU-minutes).
constexpr long kMaxSwitchesPerOutput = 10000;

}  // namespace

MasslessCableIntegrator::MasslessCableIntegrator(const TensegrityStructure& s, const MasslessCableSettings& o)
    : s_(s), settings_(o) {
  if (!s_.finalized()) throw InputError("massless cables: the tensegrity structure is not finalized");
  for (int c = 0; c < s_.numCables(); ++c) {
    if (s_.cable(c).inextensible) {
      throw InputError("cable \"" + s_.cable(c).name +
                       "\": inextensible, but method \"massless_cables\" needs every cable elastic (give it EA, or "
                       "use method \"time_stepping\")");
    }
  }
  if (!(o.tEnd > o.tStart)) throw InputError("solver.t_end must be > t_start, got " + num(o.tEnd));
  if (!(o.outputStep > 0.0)) throw InputError("solver.output_step must be > 0, got " + num(o.outputStep));
  if (!((o.tEnd - o.tStart) / o.outputStep <= 1e8)) {  // as `run` (simulation/simulation.cpp, kMaxOutputs)
    throw InputError("solver.output_step: at most 1e8 outputs over t_end - t_start expected, got " +
                     num((o.tEnd - o.tStart) / o.outputStep));
  }
  if (s_.numFreeCoordinates() == 0) throw InputError("massless cables: every node coordinate is fixed");
}

TensegrityRunSummary MasslessCableIntegrator::run(const TensegrityObserver& observer) const {
  const MasslessCableSettings& o = settings_;
  const std::clock_t cpuStart = std::clock();
  const int nc = s_.numCables();
  const int nf = s_.numFreeCoordinates();
  TensegrityOde ode(s_);
  TensegrityRunSummary sum;
  sum.method = "massless_cables";

  VecX y(2 * nf);
  y << s_.restrict(s_.initialPositions()), s_.restrict(s_.initialVelocities());
  double t = o.tStart;
  VecX x = ode.fullPositions(y.data()), v = ode.fullVelocities(y.data());
  sum.energyStart = s_.kineticEnergy(v) + s_.potentialEnergy(x);

  std::optional<MemberContactDetector> contacts;
  std::vector<TensegrityEvent> pending;
  auto emit = [&](const TensegrityEvent& e) {
    sum.count(e);
    if (observer.onEvent) observer.onEvent(e);
  };
  if (o.detectContacts) {
    contacts.emplace(s_);
    contacts->start(t, x, pending);
    for (const auto& e : pending) emit(e);
    pending.clear();
  }
  const CvodeSolver* solverSeen = nullptr;  // the steps of the samples
  auto sample = [&]() {
    if (!observer.onSample) return;
    TensegritySample smp;
    smp.t = t;
    smp.steps = solverSeen ? solverSeen->stats().steps : 0;
    smp.x = x;
    smp.v = v;
    smp.cableLength = s_.cableLengths(x);
    smp.cableTension = s_.elasticCableTensions(x);
    smp.cableImpulse = VecX::Zero(nc);  // massless cables: no impulse at a snap
    smp.slack.resize(nc);
    for (int c = 0; c < nc; ++c) {
      smp.slack[c] = smp.cableLength[c] < s_.cable(c).naturalLength * (1.0 - o.slackTolerance);
    }
    smp.kineticEnergy = s_.kineticEnergy(v);
    smp.potentialEnergy = s_.potentialEnergy(x);
    observer.onSample(smp);
  };
  sample();

  try {
    CvodeSolver solver(ode, t, y, o.cvode);
    solverSeen = &solver;
    const long nOut = std::max(1L, static_cast<long>(std::ceil((o.tEnd - o.tStart) / o.outputStep - 1e-9)));
    for (long k = 1; k <= nOut; ++k) {
      const double tout = k == nOut ? o.tEnd : o.tStart + k * o.outputStep;
      // an event storm (switches ever closer together) ends the run: bounded switches and
      // steps per output interval (docs/tensegrity.md, "Bounds of a run")
      const double tInterval = t;
      const long stepsAtInterval = solver.stats().steps;
      long switches = 0;
      std::vector<long> switchesOf(nc, 0);
      while (true) {
        const double tPrev = t;
        const VecX xPrev = x;
        t = solver.advance(tout);
        x = ode.fullPositions(solver.y().data());
        v = ode.fullVelocities(solver.y().data());
        if (contacts) {
          contacts->advance(tPrev, xPrev, t, x, pending);
          std::sort(pending.begin(), pending.end(),
                    [](const TensegrityEvent& a, const TensegrityEvent& b) { return a.t < b.t; });
          for (auto& e : pending) {
            e.step = solver.stats().steps;
            emit(e);
          }
          pending.clear();
        }
        if (!solver.rootFound()) break;
        for (int c = 0; c < nc; ++c) {
          const int dir = solver.rootsFound()[c];
          if (dir == 0) continue;
          TensegrityEvent e;
          e.type = dir > 0 ? TensegrityEvent::Type::Taut : TensegrityEvent::Type::Slack;
          e.t = t;
          e.step = solver.stats().steps;
          e.member = s_.cable(c).name;
          emit(e);
          ++switches;
          ++switchesOf[c];
        }
        const long intervalSteps = solver.stats().steps - stepsAtInterval;
        if (switches > kMaxSwitchesPerOutput || intervalSteps > o.cvode.maxSteps) {
          const int worst = static_cast<int>(std::max_element(switchesOf.begin(), switchesOf.end()) - switchesOf.begin());
          throw SolverError("event storm: " + std::to_string(switches) + " cable switches (taut/slack) and " +
                                std::to_string(intervalSteps) + " steps between t = " + num(tInterval) +
                                " and t = " + num(t) + " without reaching the next output at t = " + num(tout) +
                                " (at most " + std::to_string(kMaxSwitchesPerOutput) + " switches and max_steps = " +
                                std::to_string(o.cvode.maxSteps) + " steps per output interval); cable \"" +
                                s_.cable(worst).name + "\" switched " + std::to_string(switchesOf[worst]) +
                                " times: the switching times converge (a node mass tiny beside the cable's "
                                "stiffness, or a cable at its natural length at rest)",
                            t, solver.stats().lastStepSize);
        }
        // The cable force is only C0 at a switch: restart the multistep method there.
        solver.reinit(t, solver.y());
        if (t >= tout) break;
      }
      sample();
    }
    const CvodeStats st = solver.stats();
    sum.steps = st.steps;
    sum.rhsEvals = st.rhsEvals;
    sum.rootEvals = st.rootEvals;
    sum.errorTestFailures = st.errorTestFailures;
    sum.nonlinearConvFailures = st.nonlinearConvFailures;
    sum.ok = true;
    sum.message = "ok";
  } catch (const SolverError& e) {
    sum.ok = false;
    sum.message = e.what();
  }
  sum.tReached = t;
  sum.energyEnd = s_.kineticEnergy(v) + s_.potentialEnergy(x);
  sum.cpuSeconds = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC;
  return sum;
}

}  // namespace flexmbd
