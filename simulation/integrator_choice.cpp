#include "simulation/integrator_choice.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "analysis/elastic_modes.hpp"
#include "analysis/linearization.hpp"
#include "analysis/quasi_static_start.hpp"

namespace flexmbd {
namespace {

/// Figures in the choice's reason: three significant digits.
std::string fig(double x) { return fmt(x, 3); }

bool hasElasticCoordinates(const System& sys) {
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds();
  return std::find(kinds.begin(), kinds.end(), CoordinateKind::Elastic) != kinds.end();
}

}  // namespace

FastestRate fastestLinearRate(const System& sys, const SolverSettings& settings) {
  FastestRate r;
  // the reduction's dense SVD of G is O(nv^3): large models are not analysed
  if (sys.numVelocities() > kMaxStiffnessAnalysisVelocities) return r;
  try {
    const ConsistentState init =
        computeConsistentState(sys, settings.tStart, sys.initialCoordinates(), sys.initialVelocities());
    ReferenceState ref;
    ref.t = settings.tStart;
    ref.q = init.q, ref.v = init.v, ref.a = init.a, ref.lambda = init.lambda;
    const ReducedSystem red = reduce(linearize(sys, ref));
    const int nx = static_cast<int>(red.M.rows());
    if (nx == 0 || nx > kMaxStiffnessAnalysisSize) return r;
    ModesOptions o;
    o.count = 2 * nx;  // all of them: the fastest is the last
    o.solver = EigenSolverKind::Dense;
    for (const Mode& m : computeModes(red, o)) {
      if (m.omega > r.omega) r.omega = m.omega, r.dampingRatio = m.dampingRatio;
    }
    r.analysed = true;
  } catch (const InputError&) {  // not assembled, redundant, a singular mass: no estimate
    return FastestRate{};
  }
  return r;
}

double outputNyquistFrequency(const SolverSettings& settings) { return M_PI / settings.outputStep; }

std::string stiffModelIdaWarning(const System& sys, const SolverSettings& settings) {
  if (hasElasticCoordinates(sys)) return "";
  const FastestRate fast = fastestLinearRate(sys, settings);
  const double nyquist = outputNyquistFrequency(settings);
  if (!fast.analysed || fast.omega <= kStiffRateOverNyquist * nyquist) return "";
  return "ida on a stiff model: its fastest linearised eigenvalue at the start, |s| = " + fig(fast.omega) +
         " /s, is above the output Nyquist frequency " + fig(nyquist) +
         " rad/s; BDF's per-step errors can add up to hundreds of times rtol along a free motion there (the free "
         "A05 governor: 270 to 1,500 x rtol); \"integrator\": \"auto\" takes radau5 (docs/stability.md, section 7)";
}

IntegratorChoice chooseIntegrator(const System& sys, const SolverSettings& settings) {
  IntegratorChoice c;
  if (settings.integrator != IntegratorKind::Automatic) {
    c.kind = settings.integrator;
    c.reason = "given in the settings";
    if (c.kind == IntegratorKind::Ida) c.warning = stiffModelIdaWarning(sys, settings);
    return c;
  }
  c.kind = IntegratorKind::Ida;
  if (settings.finiteDifferenceJacobian || settings.maxOrder != 5) {
    c.reason = std::string("IDA's own option ") + (settings.finiteDifferenceJacobian ? "fd_jacobian" : "max_order") +
               " given: ida";
    c.warning = stiffModelIdaWarning(sys, settings);
    return c;
  }
  if (!hasElasticCoordinates(sys)) {
    // stiff force elements (docs/stability.md, "Stiff force elements"):
    // the model's fastest linearised eigenvalue at the start above the output Nyquist
    // frequency: a stiff spring or damper, whose fast motion is not content. BDF's sharp
    // local error estimate then lets the errors of a free (neutrally stable) motion, the
    // phase of a free spin, add up to 100 ... 1500 times rtol (the free A05 governor);
    // Radau IIA's stays within 60 times rtol there.
    const FastestRate fast = fastestLinearRate(sys, settings);
    if (fast.analysed && fast.omega > kStiffRateOverNyquist * outputNyquistFrequency(settings)) {
      c.kind = IntegratorKind::Radau5;
      c.reason = "no elastic coordinates, but the linearised model's fastest eigenvalue at the start, |s| = " +
                 fig(fast.omega) + " /s (damping ratio " + fig(fast.dampingRatio) +
                 "), is above the output Nyquist frequency " + fig(outputNyquistFrequency(settings)) +
                 " rad/s (a stiff spring or damper, or a fast spin): radau5 (L-stable Radau IIA; BDF's errors on a "
                 "free motion grew to hundreds of times rtol on such a model, docs/stability.md)";
      return c;
    }
    c.reason = "no elastic coordinates: ida (variable-order BDF) on the smooth rigid motion";
    if (fast.analysed) c.reason += " (fastest linearised eigenvalue " + fig(fast.omega) + " /s)";
    return c;
  }
  std::vector<std::string> skipped;
  const std::vector<BodyModes> modes = elasticModes(sys, &skipped, false);
  const double nyquist = outputNyquistFrequency(settings);
  const BodyModes* fastest = nullptr;  // the nodal body with the highest frequency above the Nyquist frequency
  double topModal = 0.0;               // the highest frequency of the other bodies
  for (const BodyModes& m : modes) {
    const double top = m.omega[m.size() - 1];
    if (!m.nodal || top <= nyquist) {
      topModal = std::max(topModal, top);
      continue;
    }
    c.energyWeights.push_back({m.name, m.velocityOffset, m.coordinateOffset, m.size(), top});
    if (!fastest || top > fastest->omega[fastest->size() - 1]) fastest = &m;
  }
  if (!fastest) {
    if (modes.empty()) {
      c.reason = "elastic bodies without a modal analysis (above " + std::to_string(kMaxElasticModesSize) +
                 " elastic coordinates each): ida";
    } else if (topModal > nyquist) {
      // the model keeps modes faster than its outputs: each is content, to be resolved
      // over many periods, where the high orders take the longest steps
      c.kind = IntegratorKind::Radau;
      c.reason = "elastic modes up to " + fig(topModal) + " rad/s, above the output Nyquist frequency " +
                 fig(nyquist) +
                 " rad/s and kept by the model (each one is content, resolved over many periods): radau "
                 "(Radau IIA, orders 5 to 13)";
    } else {
      c.reason = "elastic modes up to " + fig(topModal) + " rad/s, below the output Nyquist frequency " +
                 fig(nyquist) + " rad/s: ida (variable-order BDF)";
    }
    return c;
  }
  // order 5: the mesh modes are damped, not resolved, and the higher orders' costlier
  // steps do not pay there (demo rod: radau 2,706 steps and 1.3 times radau5's CPU)
  c.kind = IntegratorKind::Radau5;
  c.reason = "nodal body '" + fastest->name + "' has elastic modes up to " + fig(fastest->omega[fastest->size() - 1]) +
             " rad/s, above the output Nyquist frequency " + fig(nyquist) +
             " rad/s: radau5 (L-stable: damps the mesh modes it does not resolve), elastic velocity errors weighed "
             "in energy (atol of q_f' = omega_max x atol of q_f)";
  return c;
}

void applyEnergyVelocityWeights(const IntegratorChoice& choice, const DaeLayout& layout, VecX& atol) {
  for (const EnergyVelocityWeight& w : choice.energyWeights) {
    for (int i = 0; i < w.size; ++i) {
      double& v = atol[layout.v + w.velocityOffset + i];
      v = std::max(v, w.omega * atol[layout.q + w.coordinateOffset + i]);  // dv / omega is a displacement error
    }
  }
}

ConsistentState elasticStartState(const System& sys, const SolverSettings& settings, const ConsistentState& init,
                                  std::string& report) {
  report.clear();
  if (settings.elasticStart != ElasticStart::QuasiStatic) return init;
  const double cutoff = settings.quasiStaticAbove.value_or(outputNyquistFrequency(settings));
  const QuasiStaticStart qs = quasiStaticElasticStart(sys, settings.tStart, init, elasticModes(sys), cutoff);
  report = "quasi-static: " + std::to_string(qs.modes) + " elastic modes above " + fig(cutoff) +
           " rad/s started at their quasi-static deflection and rate (" + std::to_string(qs.iterations) +
           " iterations, remaining modal acceleration / omega^2 " + fig(qs.residual) + ")";
  return qs.state;
}

}  // namespace flexmbd
