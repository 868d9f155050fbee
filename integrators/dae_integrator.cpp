#include "integrators/dae_integrator.hpp"

#include "core/errors.hpp"
#include "core/dae_system.hpp"
#include "integrators/augmented_lagrangian_integrator.hpp"
#include "integrators/ida_solver.hpp"
#include "integrators/radau_solver.hpp"

namespace flexmbd {

std::string toString(LinearSolverKind k) {
  switch (k) {
    case LinearSolverKind::Automatic: return "auto";
    case LinearSolverKind::Dense: return "dense";
    case LinearSolverKind::Klu: return "klu";
  }
  return "?";
}

LinearSolverKind parseLinearSolver(const std::string& name) {
  if (name == "auto") return LinearSolverKind::Automatic;
  if (name == "dense") return LinearSolverKind::Dense;
  if (name == "klu") return LinearSolverKind::Klu;
  throw InputError("solver.linear_solver: unknown linear solver '" + name +
                   "' (expected one of: auto, dense, klu)");
}

std::string toString(IntegratorKind k) {
  switch (k) {
    case IntegratorKind::Ida: return "ida";
    case IntegratorKind::Radau5: return "radau5";
    case IntegratorKind::Radau: return "radau";
    case IntegratorKind::AugmentedLagrangian: return "ali3p";
    case IntegratorKind::Automatic: return "auto";
  }
  return "?";
}

IntegratorKind parseIntegrator(const std::string& name) {
  if (name == "ida") return IntegratorKind::Ida;
  if (name == "radau5") return IntegratorKind::Radau5;
  if (name == "radau") return IntegratorKind::Radau;
  if (name == "ali3p") return IntegratorKind::AugmentedLagrangian;
  if (name == "auto") return IntegratorKind::Automatic;
  throw InputError("solver.integrator: unknown integrator '" + name + "' (expected one of: auto, ida, radau, radau5, ali3p)");
}

std::unique_ptr<DaeIntegrator> makeIntegrator(IntegratorKind kind, const DaeProblem& dae, double t0,
                                              const VecX& y0, const VecX& yp0, const IntegratorOptions& options) {
  switch (kind) {
    case IntegratorKind::Ida: return std::make_unique<IdaSolver>(dae, t0, y0, yp0, options);
    case IntegratorKind::Radau5: return std::make_unique<RadauSolver>(dae, t0, y0, yp0, options, RadauStages{3, 3, 3});
    case IntegratorKind::Radau: return std::make_unique<RadauSolver>(dae, t0, y0, yp0, options, RadauStages{3, 7, 3});
    case IntegratorKind::AugmentedLagrangian: {
      const auto* model = dynamic_cast<const DaeSystem*>(&dae);
      if (!model) throw InputError("solver.integrator: ali3p integrates the engine's own models only");
      return std::make_unique<AugmentedLagrangianSolver>(*model, t0, y0, yp0, options);
    }
    case IntegratorKind::Automatic:
      throw InputError("solver.integrator: \"auto\" is resolved by the run (chooseIntegrator), not an integrator");
  }
  throw InputError("solver.integrator: unknown integrator kind");
}

}  // namespace flexmbd
