#include "integrators/dae_integrator.hpp"

#include "core/errors.hpp"
#include "integrators/ida_solver.hpp"
#include "integrators/radau5_solver.hpp"

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
  }
  return "?";
}

IntegratorKind parseIntegrator(const std::string& name) {
  if (name == "ida") return IntegratorKind::Ida;
  if (name == "radau5") return IntegratorKind::Radau5;
  throw InputError("solver.integrator: unknown integrator '" + name + "' (expected one of: ida, radau5)");
}

std::unique_ptr<DaeIntegrator> makeIntegrator(IntegratorKind kind, const DaeProblem& dae, double t0,
                                              const VecX& y0, const VecX& yp0, const IntegratorOptions& options) {
  switch (kind) {
    case IntegratorKind::Ida: return std::make_unique<IdaSolver>(dae, t0, y0, yp0, options);
    case IntegratorKind::Radau5: return std::make_unique<Radau5Solver>(dae, t0, y0, yp0, options);
  }
  throw InputError("solver.integrator: unknown integrator kind");
}

}  // namespace flexmbd
