// An exception thrown by a model's residual, Jacobian or
// right-hand side that is not a solver failure (InputError, ModelError, std::logic_error)
// crosses the integrator with its type and message, so that the caller can report it as
// what it is (the command line: exit 2 for input and model errors) and not as a solver
// failure (SolverError, exit 1). Each once came back as a SolverError. A
// non-finite residual stays a recoverable solver event: the
// integrator retries with a smaller step, and gives up with a SolverError only if the
// residual stays non-finite. Through IDA (dense and KLU), Radau IIA (dense and KLU), both
// by makeIntegrator, and CVODE.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "core/dae_problem.hpp"
#include "core/errors.hpp"
#include "integrators/cvode_solver.hpp"
#include "integrators/dae_integrator.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/force.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"

using namespace flexmbd;

namespace {

/// The models below misbehave from this time on, after some steps were taken.
constexpr double kTrouble = 0.05;
constexpr double kEnd = 1.0;
/// The oscillator x' = v, v' = -w^2 x, w = 2; x = cos(w t).
constexpr double kOmega = 2.0;

enum class Where { Residual, Jacobian };
enum class Fault { Throw, NanOnce, NanAlways };

/// What a model throws: the exception is made by `raise` (an InputError, a ModelError,
/// a std::logic_error, ...).
using Raise = std::function<void()>;

/// The oscillator as the DAE x' - v = 0, v' + w^2 x = 0 with a full pattern (so that KLU
/// sees entries the Jacobian writes), misbehaving at `where` once t > kTrouble.
class FaultyDae final : public DaeProblem {
 public:
  FaultyDae(Where where, Fault fault, Raise raise) : where_(where), fault_(fault), raise_(std::move(raise)) {
    pattern_ = SparsePattern(2, {{0, 0}, {1, 0}, {0, 1}, {1, 1}});
  }
  int size() const override { return 2; }
  const SparsePattern& pattern() const override { return pattern_; }
  VecX differentialIds() const override { return VecX::Ones(2); }
  void residual(double t, const double* y, const double* yp, double* F, DaeScratch&) const override {
    ++residualCalls;
    F[0] = yp[0] - y[1];
    F[1] = yp[1] + kOmega * kOmega * y[0];
    if (where_ == Where::Residual && t > kTrouble) misbehave(F);
  }
  void jacobian(double t, const double*, const double*, double cj, JacobianSink& J, DaeScratch&) const override {
    ++jacobianCalls;
    if (where_ == Where::Jacobian && t > kTrouble) raise_();
    J.add(0, 0, cj);
    J.add(0, 1, -1.0);
    J.add(1, 0, kOmega * kOmega);
    J.add(1, 1, cj);
  }
  mutable long residualCalls = 0, jacobianCalls = 0;

 private:
  void misbehave(double* F) const {
    if (fault_ == Fault::Throw) raise_();
    if (fault_ == Fault::NanAlways || (fault_ == Fault::NanOnce && !nanGiven_)) {
      nanGiven_ = true;
      F[1] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  Where where_;
  Fault fault_;
  Raise raise_;
  SparsePattern pattern_;
  mutable bool nanGiven_ = false;
};

/// The same oscillator as the ODE for CVODE, with one root function x (sign changes at
/// the quarter periods).
class FaultyOde final : public OdeSystem {
 public:
  FaultyOde(bool inRoots, Fault fault, Raise raise) : inRoots_(inRoots), fault_(fault), raise_(std::move(raise)) {}
  int size() const override { return 2; }
  int numRoots() const override { return 1; }
  void rhs(double t, const double* y, double* ydot) const override {
    ydot[0] = y[1];
    ydot[1] = -kOmega * kOmega * y[0];
    if (inRoots_ || !(t > kTrouble)) return;
    if (fault_ == Fault::Throw) raise_();
    if (fault_ == Fault::NanAlways || (fault_ == Fault::NanOnce && !nanGiven_)) {
      nanGiven_ = true;
      ydot[1] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  void roots(double t, const double* y, double* g) const override {
    if (inRoots_ && t > kTrouble) raise_();
    g[0] = y[0];
  }

 private:
  bool inRoots_;
  Fault fault_;
  Raise raise_;
  mutable bool nanGiven_ = false;
};

VecX exact(double t) { return Eigen::Vector2d(std::cos(kOmega * t), -kOmega * std::sin(kOmega * t)); }

/// An exception of each kind the command line tells apart, with its message.
struct Kind {
  const char* label;
  const std::type_info& type;
  std::string message;
  Raise raise;
};
std::vector<Kind> kinds() {
  return {
      {"InputError", typeid(InputError), "force 'push': load table ends at t = 0.05",
       [] { throw InputError("force 'push': load table ends at t = 0.05"); }},
      {"ModelError", typeid(ModelError), "joint 'pin': cannot be assembled",
       [] { throw ModelError("joint 'pin': cannot be assembled"); }},
      {"std::logic_error", typeid(std::logic_error), "JacobianSink: entry (5, 7) outside the pattern",
       [] { throw std::logic_error("JacobianSink: entry (5, 7) outside the pattern"); }},
  };
}

struct IntegratorSetup {
  const char* label;
  IntegratorKind kind;
  LinearSolverKind linearSolver;
};
const IntegratorSetup kSetups[] = {
    {"ida dense", IntegratorKind::Ida, LinearSolverKind::Dense},
    {"ida klu", IntegratorKind::Ida, LinearSolverKind::Klu},
    {"radau5 dense", IntegratorKind::Radau5, LinearSolverKind::Dense},
    {"radau5 klu", IntegratorKind::Radau5, LinearSolverKind::Klu},
};

IntegratorOptions options(LinearSolverKind ls) {
  IntegratorOptions o;
  o.rtol = 1e-8;
  o.atol = VecX::Constant(2, 1e-8);
  o.linearSolver = ls;
  o.minStepSize = 1e-12;  // a residual that stays non-finite ends the run at once
  return o;
}

/// Integrates the oscillator from t0 (on its exact solution) to kEnd in outputs of 0.01
/// with the given integrator. Returns the exception that left advance(), or null.
std::exception_ptr integrate(const IntegratorSetup& s, const FaultyDae& dae, double t0 = 0.0, VecX* yEnd = nullptr) {
  const VecX y0 = exact(t0);
  const VecX yp0 = (VecX(2) << y0[1], -kOmega * kOmega * y0[0]).finished();
  const std::unique_ptr<DaeIntegrator> integrator = makeIntegrator(s.kind, dae, t0, y0, yp0, options(s.linearSolver));
  try {
    for (double t = t0; t < kEnd;) t = integrator->advance(std::min(kEnd, t + 0.01), kEnd);
  } catch (...) {
    return std::current_exception();
  }
  if (yEnd) *yEnd = integrator->y();
  return nullptr;
}

std::exception_ptr integrate(const FaultyOde& ode, VecX* yEnd = nullptr) {
  CvodeOptions o;
  o.rtol = o.atol = 1e-8;
  o.maxSteps = 100000;  // a right-hand side that stays non-finite strands CVODE at t = kTrouble
  CvodeSolver solver(ode, 0.0, (VecX(2) << 1.0, 0.0).finished(), o);
  try {
    double t = 0.0;
    while (t < kEnd) {
      t = solver.advance(kEnd);
      if (solver.rootFound()) solver.reinit(t, solver.y());
    }
  } catch (...) {
    return std::current_exception();
  }
  if (yEnd) *yEnd = solver.y();
  return nullptr;
}

/// The dynamic type of the exception and its message.
std::pair<const std::type_info*, std::string> typeAndMessage(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return {&typeid(x), x.what()};
  } catch (...) {
    return {&typeid(void), "(not a std::exception)"};
  }
}

void expectArrivesUnchanged(const std::exception_ptr& e, const Kind& k, const std::string& where) {
  ASSERT_TRUE(e) << where << ": the " << k.label << " thrown by the model did not stop the integration";
  const auto [type, message] = typeAndMessage(e);
  EXPECT_TRUE(*type == k.type) << where << ": a " << k.label << " was thrown by the model, a " << type->name()
                               << " arrived: " << message;
  EXPECT_EQ(message, k.message) << where;
}

}  // namespace

TEST(ExceptionTypes, ResidualExceptionsCrossDaeIntegratorsWithTheirType) {
  for (const IntegratorSetup& s : kSetups) {
    for (const Kind& k : kinds()) {
      const FaultyDae dae(Where::Residual, Fault::Throw, k.raise);
      expectArrivesUnchanged(integrate(s, dae), k, std::string(s.label) + ", residual");
      EXPECT_GT(dae.residualCalls, 10) << s.label << ": the model was to throw after some steps, not at once";
    }
  }
}

TEST(ExceptionTypes, JacobianExceptionsCrossDaeIntegratorsWithTheirType) {
  // Radau IIA keeps the Jacobian of its first step for this linear model (its Newton
  // iteration converges at once), so the run starts where the Jacobian throws: at its
  // first evaluation, inside advance().
  for (const IntegratorSetup& s : kSetups) {
    for (const Kind& k : kinds()) {
      const FaultyDae dae(Where::Jacobian, Fault::Throw, k.raise);
      expectArrivesUnchanged(integrate(s, dae, 2 * kTrouble), k, std::string(s.label) + ", Jacobian");
      EXPECT_GE(dae.jacobianCalls, 1) << s.label;
    }
  }
}

TEST(ExceptionTypes, RightHandSideAndRootExceptionsCrossCvodeWithTheirType) {
  for (const Kind& k : kinds()) {
    expectArrivesUnchanged(integrate(FaultyOde(false, Fault::Throw, k.raise)), k, "cvode, right-hand side");
    expectArrivesUnchanged(integrate(FaultyOde(true, Fault::Throw, k.raise)), k, "cvode, root function");
  }
}

TEST(ExceptionTypes, ANonFiniteResidualStaysARecoverableSolverEvent) {
  const Raise never = [] {};
  // once: the integrator retries with a smaller step and reaches the end accurately
  for (const IntegratorSetup& s : kSetups) {
    const FaultyDae dae(Where::Residual, Fault::NanOnce, never);
    VecX y;
    const std::exception_ptr e = integrate(s, dae, 0.0, &y);
    EXPECT_FALSE(e) << s.label << ": " << (e ? typeAndMessage(e).second : "");
    if (!e) EXPECT_LT((y - exact(kEnd)).norm(), 1e-5) << s.label;
  }
  {
    VecX y;
    const std::exception_ptr e = integrate(FaultyOde(false, Fault::NanOnce, never), &y);
    EXPECT_FALSE(e) << "cvode: " << (e ? typeAndMessage(e).second : "");
    if (!e) EXPECT_LT((y - exact(kEnd)).norm(), 1e-5) << "cvode";
  }
  // always: the integrator gives up, with a solver failure
  for (const IntegratorSetup& s : kSetups) {
    const std::exception_ptr e = integrate(s, FaultyDae(Where::Residual, Fault::NanAlways, never));
    ASSERT_TRUE(e) << s.label;
    EXPECT_TRUE(*typeAndMessage(e).first == typeid(SolverError)) << s.label << ": " << typeAndMessage(e).second;
  }
  const std::exception_ptr e = integrate(FaultyOde(false, Fault::NanAlways, never));
  ASSERT_TRUE(e) << "cvode";
  EXPECT_TRUE(*typeAndMessage(e).first == typeid(SolverError)) << "cvode: " << typeAndMessage(e).second;
}

namespace {

/// A load that finds its input bad at t > kTrouble (as a user's force law could), or
/// throws an assembly bug.
class FaultyLoad final : public Force {
 public:
  FaultyLoad(BodyIndex b, Raise raise) : Force("faulty", {b}), raise_(std::move(raise)) {}
  std::string typeName() const override { return "faulty"; }
  bool isConservative() const override { return false; }
  void addForce(double t, const BodyStates&, const VecX&, VecX& Q, MatX*, MatX*, KinematicsWork&) const override {
    Q[1] -= 9.81;
    if (t > kTrouble) raise_();
  }

 private:
  Raise raise_;
};

}  // namespace

TEST(ExceptionTypes, SimulateLetsInputErrorsAndAssemblyBugsThroughButReportsModelErrorsAsAFailedRun) {
  const auto run = [](Raise raise) {
    System sys;
    const BodyIndex b = addRigidBody(sys, "b", {1.0, 0.1, {0.0, 0.0}}, {});
    sys.addForce(std::make_unique<FaultyLoad>(b, std::move(raise)));
    sys.finalize();
    SolverSettings st;
    st.tEnd = kEnd;
    st.progress = false;
    return simulate(sys, st, nullptr);
  };
  EXPECT_THROW(run([] { throw InputError("load 'faulty': bad table"); }), InputError);
  try {
    run([] { throw std::logic_error("assembly bug"); });
    ADD_FAILURE() << "expected std::logic_error";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "assembly bug");
  }
  // a model error (a singular matrix at some state) ends the run as failed, results kept
  const SimulationSummary s = run([] { throw ModelError("singular"); });
  EXPECT_FALSE(s.ok);
  EXPECT_GT(s.tReached, 0.0);
}
