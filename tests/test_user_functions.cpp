// User functions (core/user_function.hpp): C++ callables as time laws
// and spring-damper laws, their finite-difference derivatives against the exact ones, a
// user law run against the same law built in and against a closed form, and an exception
// in a callable ending the run with its message and the results so far.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "builders/planar_builders.hpp"
#include "builders/spatial_builders.hpp"
#include "core/errors.hpp"
#include "core/user_function.hpp"
#include "simulation/simulation.hpp"

using namespace flexmbd;

namespace {

// ---- derivatives: finite differences against the exact ones --------------------------

// f = sin(3 t) + t^2 at t = 0.7: f''' = -27 cos(3t), f'''' = 81 sin(3t).
double f(double t) { return std::sin(3.0 * t) + t * t; }
double df(double t) { return 3.0 * std::cos(3.0 * t) + 2.0 * t; }
double ddf(double t) { return -9.0 * std::sin(3.0 * t) + 2.0; }

TEST(UserTimeLaw, FiniteDifferenceDerivativesAgreeWithTheExactOnes) {
  const double t = 0.7;
  const TimeLawPtr fd = makeUserTimeLaw(f);
  const LawValue v = fd->evaluate(t);
  EXPECT_EQ(v.f, f(t));  // the value is the callable's, untouched
  EXPECT_EQ(fd->value(t), f(t));
  // f': truncation h1^2 |f'''| / 6 with h1 = eps^(1/3) ~ 6e-6: ~1.6e-10, rounding eps |f| / h1 ~ 4e-11;
  // 1e-9 is five times their sum
  EXPECT_NEAR(v.df, df(t), 1e-9);
  // f'': truncation h2^2 |f''''| / 12 with h2 = eps^(1/4) ~ 1.2e-4: ~8e-8, rounding
  // 4 eps |f| / h2^2 ~ 6e-8; 1e-6 is seven times their sum
  EXPECT_NEAR(v.ddf, ddf(t), 1e-6);

  // f'' from the given f' by central differences of f' (h1): error ~ h1^2 |f''''| / 6 + eps |f'| / h1
  const LawValue w = makeUserTimeLaw(f, df)->evaluate(t);
  EXPECT_EQ(w.df, df(t));
  EXPECT_NEAR(w.ddf, ddf(t), 1e-9);

  // both given: taken as they are
  const LawValue x = makeUserTimeLaw(f, df, ddf)->evaluate(t);
  EXPECT_EQ(x.df, df(t));
  EXPECT_EQ(x.ddf, ddf(t));
}

TEST(UserTimeLaw, RefusesAMissingFunctionWithWords) {
  try {
    makeUserTimeLaw({});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no function given"), std::string::npos) << e.what();
  }
  try {
    makeUserTimeLaw(f, {}, ddf);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a second derivative without the first"), std::string::npos) << e.what();
  }
}

// A nonlinear spring-damper law: f = k (x - x0) + c x' + a x^3 + b x'^3 t.
constexpr double kK = 40.0, kC = 0.3, kX0 = 0.5, kA = 7.0, kB = 0.2;
double spring(double t, double x, double xdot) {
  return kK * (x - kX0) + kC * xdot + kA * x * x * x + kB * xdot * xdot * xdot * t;
}
std::array<double, 2> springDerivative(double t, double x, double xdot) {
  return {kK + 3.0 * kA * x * x, kC + 3.0 * kB * xdot * xdot * t};
}

TEST(UserSpringLaw, FiniteDifferenceDerivativesAgreeWithTheUserOnes) {
  const SpringLaw fd(spring);
  const SpringLaw exact(spring, springDerivative);
  EXPECT_FALSE(fd.hasUserDerivative());
  EXPECT_TRUE(exact.hasUserDerivative());
  for (const auto& [t, x, xdot] : {std::array<double, 3>{0.3, 0.8, -1.5}, {2.0, 0.01, 0.0}, {5.0, -3.0, 4.0}}) {
    const SpringLawValue a = fd.evaluate(t, x, xdot, true);
    const SpringLawValue b = exact.evaluate(t, x, xdot, true);
    EXPECT_EQ(a.f, b.f);
    EXPECT_EQ(a.f, spring(t, x, xdot));
    // central differences, h = eps^(1/3) max(|x|, 1): truncation h^2 |f'''| / 6 (f''' = 6a or
    // 6 b t) and rounding eps |f| / h: below 1e-8 relative at these points
    EXPECT_NEAR(a.dfdx, b.dfdx, 1e-8 * std::abs(b.dfdx)) << "t = " << t;
    EXPECT_NEAR(a.dfdxdot, b.dfdxdot, 1e-8 * std::max(std::abs(b.dfdxdot), 1.0)) << "t = " << t;
  }
  // without derivatives: one call, derivatives zero
  const SpringLawValue v = fd.evaluate(0.3, 0.8, -1.5, false);
  EXPECT_EQ(v.dfdx, 0.0);
  EXPECT_EQ(v.dfdxdot, 0.0);
}

// ---- runs ----------------------------------------------------------------------------

/// A pendulum (rod of 1 kg, 1 m, pinned at one end, gravity -y) driven by a torque law.
struct Pendulum {
  System sys;
  BodyIndex rod;
};
void buildPendulum(Pendulum& p, TimeLawPtr torque) {
  p.sys.setGravity(Vec2(0.0, -9.81));
  p.rod = addRigidBody(p.sys, "rod", {1.0, 1.0 / 12.0, Vec2(0.0, 0.0)}, {Vec2(0.5, 0.0), 0.0, Vec2::Zero(), 0.0});
  addRevoluteJoint(p.sys, "pin", kGround, Vec2::Zero(), p.rod, Vec2(-0.5, 0.0));
  addAppliedLoad(p.sys, "motor", p.rod, Vec2::Zero(), nullptr, nullptr, std::move(torque));
  p.sys.finalize();
}

std::vector<OutputSample> run(const System& sys, const SolverSettings& st, SimulationSummary* summary = nullptr) {
  std::vector<OutputSample> out;
  const SimulationSummary s = simulateKeepingFailures(sys, st, [&](const OutputSample& o) { out.push_back(o); });
  if (summary) *summary = s;
  return out;
}

SolverSettings settings(double tEnd) {
  SolverSettings st;
  st.tEnd = tEnd;
  st.outputStep = 0.01;
  st.progress = false;
  return st;
}

TEST(UserTimeLaw, TorqueLawRunEqualsTheBuiltInLawBitForBit) {
  // the harmonic law computes offset + A sin(omega t + phase) (core/time_law.cpp); the
  // callable does the same operations, so every residual and Jacobian is the same number
  constexpr double A = 2.0, w = 5.0;
  Pendulum builtIn, user;
  buildPendulum(builtIn, makeHarmonicLaw(A, w));
  buildPendulum(user, makeUserTimeLaw([](double t) { return 0.0 + A * std::sin(w * t + 0.0); }));
  SimulationSummary sa, sb;
  const std::vector<OutputSample> a = run(builtIn.sys, settings(1.0), &sa);
  const std::vector<OutputSample> b = run(user.sys, settings(1.0), &sb);
  ASSERT_TRUE(sa.ok) << sa.message;
  ASSERT_TRUE(sb.ok) << sb.message;
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].t, b[k].t);
    EXPECT_TRUE(a[k].q == b[k].q) << "q differs at t = " << a[k].t;
    EXPECT_TRUE(a[k].v == b[k].v) << "v differs at t = " << a[k].t;
    EXPECT_TRUE(a[k].a == b[k].a) << "a differs at t = " << a[k].t;
    EXPECT_TRUE(a[k].lambda == b[k].lambda) << "lambda differs at t = " << a[k].t;
  }
  EXPECT_EQ(sa.stats.steps, sb.stats.steps);
}

/// u(t) = x(t) - l0 of m u'' + c u' + k u = 0, u(0) = u0, u'(0) = 0, underdamped:
/// u = e^(-zeta wn t) (u0 cos(wd t) + zeta wn u0 / wd sin(wd t)) (any vibrations text,
/// e.g. Rao, Mechanical Vibrations, 2.6).
double dampedOscillator(double m, double k, double c, double u0, double t) {
  const double wn = std::sqrt(k / m);
  const double zeta = c / (2.0 * std::sqrt(k * m));
  const double wd = wn * std::sqrt(1.0 - zeta * zeta);
  return std::exp(-zeta * wn * t) * (u0 * std::cos(wd * t) + zeta * wn * u0 / wd * std::sin(wd * t));
}

TEST(UserSpringLaw, PlanarMassOnASpringDamperFollowsTheClosedForm) {
  // a 2 kg slider on a prismatic joint along x, a spring-damper from the origin given as
  // a C++ law f = k (l - l0) + c l' (finite-difference derivatives)
  constexpr double m = 2.0, k = 50.0, c = 0.8, l0 = 1.0, x0 = 1.3;
  System sys;
  const BodyIndex slider = addRigidBody(sys, "slider", {m, 0.1, Vec2::Zero()}, {Vec2(x0, 0.0), 0.0, Vec2::Zero(), 0.0});
  addPrismaticJoint(sys, "rail", kGround, Vec2::Zero(), slider, Vec2::Zero(), Vec2(1.0, 0.0));
  addSpringDamper(sys, "spring", kGround, Vec2::Zero(), slider, Vec2::Zero(), 0.0, 0.0, 0.0,
                  makeSpringLaw([&](double, double l, double ldot) { return k * (l - l0) + c * ldot; }));
  sys.finalize();
  SimulationSummary s;
  const std::vector<OutputSample> out = run(sys, settings(3.0), &s);  // about 3.4 periods
  ASSERT_TRUE(s.ok) << s.message;
  const int ix = sys.coordinateOffset(slider);
  double worst = 0.0;
  for (const OutputSample& o : out) {
    worst = std::max(worst, std::abs(o.q[ix] - l0 - dampedOscillator(m, k, c, x0 - l0, o.t)));
  }
  // BDF at rtol 1e-8, atol 1e-10: the global error after ~3 periods is a few hundred
  // times rtol times the amplitude 0.3 m; 1e-5 m bounds it (0.003 % of the amplitude)
  EXPECT_LT(worst, 1e-5);
}

TEST(UserSpringLaw, SpatialTorsionSpringFollowsTheClosedForm) {
  // a body on a spatial revolute joint about z with a torsion law tau = k theta + c theta'
  // (user derivative), started at rest at theta = 0 with angular velocity w0:
  // theta = e^(-zeta wn t) (w0 / wd) sin(wd t) (the same oscillator, u(0) = 0, u'(0) = w0)
  constexpr double J = 0.4, k = 20.0, c = 0.1, w0 = 1.5;
  System sys;
  RigidBody3dProperties props;
  props.mass = 3.0;
  props.inertia = Vec3(0.3, 0.35, J).asDiagonal();
  FrameState3d init;
  init.angularVelocity = Vec3(0.0, 0.0, w0);
  const BodyIndex disc = addRigidBody3d(sys, "disc", props, init);
  const Vec3 axis(0.0, 0.0, 1.0);
  const ConstraintIndex hinge = addSpatialJointAtWorld(sys, "hinge", SpatialJointType::Revolute, kGround, disc,
                                                       Vec3::Zero(), &axis);
  addSpatialRotationalSpringDamper(
      sys, "torsion", hinge, 0.0, 0.0, 0.0,
      makeSpringLaw([&](double, double th, double thdot) { return k * th + c * thdot; },
                    [&](double, double, double) { return std::array<double, 2>{k, c}; }));
  sys.finalize();
  SimulationSummary s;
  const std::vector<OutputSample> out = run(sys, settings(2.0), &s);
  ASSERT_TRUE(s.ok) << s.message;
  const int iq = sys.coordinateOffset(disc) + 3;  // Euler parameters e0..e3
  const double wn = std::sqrt(k / J), zeta = c / (2.0 * std::sqrt(k * J)), wd = wn * std::sqrt(1.0 - zeta * zeta);
  double worst = 0.0;
  for (const OutputSample& o : out) {
    const double theta = 2.0 * std::atan2(o.q[iq + 3], o.q[iq]);  // rotation about z from (e0, e3)
    const double exact = std::exp(-zeta * wn * o.t) * (w0 / wd) * std::sin(wd * o.t);
    worst = std::max(worst, std::abs(theta - exact));
  }
  // amplitude w0 / wd ~ 0.21 rad over ~2.3 periods; 1e-5 rad as above
  EXPECT_LT(worst, 1e-5);
}

TEST(UserSpringLaw, UserLinearLawRunsAsTheBuiltInSpring) {
  // the same linear law as a user law (FD derivatives) and built in: equal to the
  // integrator's accuracy (the derivatives differ only in the Newton matrix)
  constexpr double m = 2.0, k = 50.0, c = 0.8, l0 = 1.0;
  auto build = [&](System& sys, SpringLawPtr law) {
    const BodyIndex b = addRigidBody(sys, "slider", {m, 0.1, Vec2::Zero()}, {Vec2(1.3, 0.0), 0.0, Vec2::Zero(), 0.0});
    addPrismaticJoint(sys, "rail", kGround, Vec2::Zero(), b, Vec2::Zero(), Vec2(1.0, 0.0));
    addSpringDamper(sys, "spring", kGround, Vec2::Zero(), b, Vec2::Zero(), law ? 0.0 : k, law ? 0.0 : c, l0,
                    std::move(law));
    sys.finalize();
    return b;
  };
  System a, b;
  const BodyIndex ba = build(a, nullptr);
  build(b, makeSpringLaw([&](double, double l, double ldot) { return k * (l - l0) + c * ldot; }));
  const std::vector<OutputSample> ra = run(a, settings(1.0)), rb = run(b, settings(1.0));
  ASSERT_EQ(ra.size(), rb.size());
  const int ix = a.coordinateOffset(ba);
  double worst = 0.0;
  for (std::size_t i = 0; i < ra.size(); ++i) worst = std::max(worst, std::abs(ra[i].q[ix] - rb[i].q[ix]));
  // both within ~1e-6 m of the exact motion (test above); 1e-6 m (3e-6 of the amplitude)
  EXPECT_LT(worst, 1e-6);
}

// ---- an exception in a callable ends the run -----------------------------------------

TEST(UserFunctions, AnExceptionInASpringLawEndsTheRunWithItsMessageAndTheResultsSoFar) {
  System sys;
  const BodyIndex slider =
      addRigidBody(sys, "slider", {2.0, 0.1, Vec2::Zero()}, {Vec2(1.3, 0.0), 0.0, Vec2::Zero(), 0.0});
  addPrismaticJoint(sys, "rail", kGround, Vec2::Zero(), slider, Vec2::Zero(), Vec2(1.0, 0.0));
  addSpringDamper(sys, "spring", kGround, Vec2::Zero(), slider, Vec2::Zero(), 0.0, 0.0, 0.0,
                  makeSpringLaw([](double t, double l, double) {
                    if (t > 0.5) throw std::runtime_error("the table ends at 0.5 s");
                    return 50.0 * (l - 1.0);
                  }));
  sys.finalize();
  SimulationSummary s;
  const std::vector<OutputSample> out = run(sys, settings(1.0), &s);
  EXPECT_FALSE(s.ok);
  for (const char* words : {"force 'spring'", "the user spring law raised the table ends at 0.5 s", "at t = 0.5"}) {
    EXPECT_NE(s.message.find(words), std::string::npos) << "no '" << words << "' in: " << s.message;
  }
  // the outputs up to the failure are kept: the run got to 0.49 or 0.5 (the integrator's
  // step past an output may reach t > 0.5 before that output is interpolated), none after
  ASSERT_GE(out.size(), 50u);  // t = 0, 0.01, ..., 0.49 at least
  EXPECT_LE(out.back().t, 0.5 + 1e-12);
  EXPECT_EQ(s.tReached, out.back().t);
  EXPECT_GT(s.failureTime, 0.5);
}

TEST(UserFunctions, AnExceptionInADriverLawNamesTheDriver) {
  System sys;
  const BodyIndex rod =
      addRigidBody(sys, "rod", {1.0, 1.0 / 12.0, Vec2::Zero()}, {Vec2(0.5, 0.0), 0.0, Vec2::Zero(), 0.0});
  const ConstraintIndex pin = addRevoluteJoint(sys, "pin", kGround, Vec2::Zero(), rod, Vec2(-0.5, 0.0));
  addJointDriver(sys, "motor", pin, makeUserTimeLaw([](double t) {
                   if (t > 0.25) throw std::invalid_argument("speed table exhausted");
                   return 2.0 * t;
                 }));
  sys.finalize();
  SimulationSummary s;
  const std::vector<OutputSample> out = run(sys, settings(1.0), &s);
  EXPECT_FALSE(s.ok);
  for (const char* words : {"driver 'motor'", "the user time law raised speed table exhausted", "at t = 0.25"}) {
    EXPECT_NE(s.message.find(words), std::string::npos) << "no '" << words << "' in: " << s.message;
  }
  // the outputs before the failure are kept (how far before 0.25: one integrator step,
  // which is large on this smooth motion), none after
  ASSERT_GE(out.size(), 2u);
  EXPECT_LE(out.back().t, 0.25 + 1e-12);
  EXPECT_EQ(s.tReached, out.back().t);
}

TEST(UserFunctions, AnExceptionInALoadLawNamesTheLoad) {
  Pendulum p;
  buildPendulum(p, makeUserTimeLaw([](double t) -> double {
    if (t > 0.1) throw std::runtime_error("sensor lost");
    return 1.0;
  }));
  SimulationSummary s;
  run(p.sys, settings(1.0), &s);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("force 'motor': the user time law raised sensor lost at t = 0.1"), std::string::npos)
      << s.message;
}

}  // namespace
