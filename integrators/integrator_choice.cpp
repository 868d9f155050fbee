#include "integrators/integrator_choice.hpp"

#include <cmath>
#include <sstream>

#include "integrators/elastic_modes.hpp"
#include "integrators/quasi_static_start.hpp"

namespace flexmbd {
namespace {

std::string fmt(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

}  // namespace

double outputNyquistFrequency(const SolverSettings& settings) { return M_PI / settings.outputStep; }

IntegratorChoice chooseIntegrator(const System& sys, const SolverSettings& settings) {
  IntegratorChoice c;
  if (settings.integrator != IntegratorKind::Automatic) {
    c.kind = settings.integrator;
    c.reason = "given in the settings";
    return c;
  }
  if (settings.finiteDifferenceJacobian || settings.maxOrder != 5) {
    c.kind = IntegratorKind::Ida;
    c.reason = std::string("IDA's own option ") + (settings.finiteDifferenceJacobian ? "fd_jacobian" : "max_order") +
               " given: ida";
    return c;
  }
  std::vector<std::string> skipped;
  const std::vector<BodyModes> modes = elasticModes(sys, &skipped, false);
  const double nyquist = outputNyquistFrequency(settings);
  const BodyModes* fastest = nullptr;
  for (const BodyModes& m : modes) {
    if (m.omega[m.size() - 1] > nyquist) {
      c.energyWeights.push_back({m.name, m.velocityOffset, m.coordinateOffset, m.size(), m.omega[m.size() - 1]});
      if (!fastest || m.omega[m.size() - 1] > fastest->omega[fastest->size() - 1]) fastest = &m;
    }
  }
  if (!fastest) {
    c.kind = IntegratorKind::Ida;
    if (modes.empty() && skipped.empty()) {
      c.reason = "no elastic coordinates: ida (variable-order BDF) on the smooth rigid motion";
    } else if (modes.empty()) {
      c.reason = "elastic bodies too large to analyse (" + std::to_string(skipped.size()) +
                 ", above " + std::to_string(kMaxElasticModesSize) + " coordinates): ida";
    } else {
      double top = 0.0;
      for (const BodyModes& m : modes) top = std::max(top, m.omega[m.size() - 1]);
      c.reason = "every elastic mode (up to " + fmt(top) + " rad/s) below the output Nyquist frequency " +
                 fmt(nyquist) + " rad/s, resolved like the motion: ida (variable-order BDF)";
    }
    return c;
  }
  c.kind = IntegratorKind::Radau5;
  const double top = fastest->omega[fastest->size() - 1];
  c.reason = "body '" + fastest->name + "' has elastic modes up to " + fmt(top) +
             " rad/s, above the output Nyquist frequency " + fmt(nyquist) +
             " rad/s: radau5 (L-stable, damps the modes it does not resolve), elastic velocity errors weighed in "
             "energy (atol of q_f' = omega_max x atol of q_f)";
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
  report = "quasi-static: " + std::to_string(qs.modes) + " elastic modes above " + fmt(cutoff) +
           " rad/s started at their quasi-static deflection and rate (" + std::to_string(qs.iterations) +
           " iterations, remaining modal acceleration / omega^2 " + fmt(qs.residual) + ")";
  return qs.state;
}

}  // namespace flexmbd
