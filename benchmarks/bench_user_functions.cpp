// User functions: what a C++ callable costs per call against the
// built-in law it replaces.
//  1. A time law's value f(t) called directly, 10^7 times: the built-in harmonic law and
//     the same law as a user law (std::function behind the TimeLaw interface, the call
//     guarded by a try block), and f = t both ways: the difference per call of the latter
//     is the user function's overhead.
//  2. A spring-damper law's value and its derivatives by central differences (5 calls).
//  3. Whole runs (50 s of motion, the fastest of interleaved rounds): a pendulum driven
//     by the harmonic torque as a built-in and as a user law,
//     and a slider on a built-in and a user spring law: wall time, calls counted, and
//     (t_user - t_builtin) / calls.
//     build/benchmarks/bench_user_functions [--calls N] [--rounds R]
// The Python overhead per call: benchmarks/bench_user_functions.py.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "builders/planar_builders.hpp"
#include "core/user_function.hpp"
#include "simulation/simulation.hpp"

using namespace flexmbd;

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

constexpr double kA = 2.0, kW = 5.0;

/// The fastest of `rounds` timings of f() (a shared machine's load only adds time).
template <class F>
double fastest(int rounds, F&& f) {
  double best = 1e300;
  for (int r = 0; r < rounds; ++r) {
    const auto a = Clock::now();
    f();
    best = std::min(best, seconds(a, Clock::now()));
  }
  return best;
}

volatile double gSink = 0.0;  // keeps the loops' results alive

double timeLawLoop(const TimeLaw& law, long calls) {
  double s = 0.0;
  for (long i = 0; i < calls; ++i) s += law.value(1e-7 * static_cast<double>(i));
  gSink = s;
  return s;
}

double springLoop(const SpringLaw& law, long calls, bool derivatives) {
  double s = 0.0;
  for (long i = 0; i < calls; ++i) {
    const SpringLawValue v = law.evaluate(0.0, 1.0 + 1e-9 * static_cast<double>(i), 0.1, derivatives);
    s += v.f + v.dfdx + v.dfdxdot;
  }
  gSink = s;
  return s;
}

SolverSettings settings() {
  SolverSettings st;
  st.tEnd = 50.0;
  st.outputStep = 0.01;
  st.progress = false;
  return st;
}

double runPendulum(TimeLawPtr torque) {
  System sys;
  sys.setGravity(Vec2(0.0, -9.81));
  const BodyIndex rod =
      addRigidBody(sys, "rod", {1.0, 1.0 / 12.0, Vec2::Zero()}, {Vec2(0.5, 0.0), 0.0, Vec2::Zero(), 0.0});
  addRevoluteJoint(sys, "pin", kGround, Vec2::Zero(), rod, Vec2(-0.5, 0.0));
  addAppliedLoad(sys, "motor", rod, Vec2::Zero(), nullptr, nullptr, std::move(torque));
  sys.finalize();
  const auto a = Clock::now();
  const SimulationSummary s = simulate(sys, settings(), nullptr);
  if (!s.ok) std::fprintf(stderr, "run failed: %s\n", s.message.c_str());
  return seconds(a, Clock::now());
}

double runSlider(SpringLawPtr law) {
  System sys;
  const BodyIndex b = addRigidBody(sys, "slider", {2.0, 0.1, Vec2::Zero()}, {Vec2(1.3, 0.0), 0.0, Vec2::Zero(), 0.0});
  addPrismaticJoint(sys, "rail", kGround, Vec2::Zero(), b, Vec2::Zero(), Vec2(1.0, 0.0));
  addSpringDamper(sys, "spring", kGround, Vec2::Zero(), b, Vec2::Zero(), law ? 0.0 : 50.0, law ? 0.0 : 0.8, 1.0,
                  std::move(law));
  sys.finalize();
  const auto a = Clock::now();
  const SimulationSummary s = simulate(sys, settings(), nullptr);
  if (!s.ok) std::fprintf(stderr, "run failed: %s\n", s.message.c_str());
  return seconds(a, Clock::now());
}

}  // namespace

int main(int argc, char** argv) {
  long calls = 10000000;
  int rounds = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--calls")) calls = std::atol(argv[i + 1]);
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::atoi(argv[i + 1]);
  }

  // 1. time laws, called directly
  const TimeLawPtr builtIn = makeHarmonicLaw(kA, kW);
  const TimeLawPtr user = makeUserTimeLaw([](double t) { return 0.0 + kA * std::sin(kW * t + 0.0); });
  const double tb = fastest(rounds, [&] { timeLawLoop(*builtIn, calls); });
  const double tu = fastest(rounds, [&] { timeLawLoop(*user, calls); });
  std::printf("time law f(t), %ld calls, fastest of %d rounds\n", calls, rounds);
  std::printf("| law | ns per call |\n|---|---|\n");
  std::printf("| built-in harmonic | %.2f |\n| user (C++ lambda) | %.2f |\n", 1e9 * tb / calls, 1e9 * tu / calls);
  std::printf("| user - built-in | %.2f |\n", 1e9 * (tu - tb) / calls);
  // the harmonic law's value() computes its derivatives too (sin and cos); the call's own
  // cost shows on a law that costs nothing: f = 0 + 1 t, built in (constant_speed) and as a
  // user law (virtual call, std::function call, try block)
  const TimeLawPtr linearLaw = makeConstantSpeedLaw(1.0);
  const TimeLawPtr userLinear = makeUserTimeLaw([](double t) { return 0.0 + 1.0 * t; });
  const double lb = fastest(rounds, [&] { timeLawLoop(*linearLaw, calls); });
  const double lu = fastest(rounds, [&] { timeLawLoop(*userLinear, calls); });
  std::printf("| built-in constant_speed (f = t) | %.2f |\n| user (C++ lambda, f = t) | %.2f |\n", 1e9 * lb / calls,
              1e9 * lu / calls);
  std::printf("| overhead per call (user - built-in, f = t) | %.2f |\n\n", 1e9 * (lu - lb) / calls);

  // 2. spring laws
  const SpringLaw linear([](double, double x, double xdot) { return 50.0 * (x - 1.0) + 0.8 * xdot; });
  const SpringLaw withDerivative([](double, double x, double xdot) { return 50.0 * (x - 1.0) + 0.8 * xdot; },
                                 [](double, double, double) { return std::array<double, 2>{50.0, 0.8}; });
  const double s0 = fastest(rounds, [&] { springLoop(linear, calls, false); });
  const double s1 = fastest(rounds, [&] { springLoop(linear, calls, true); });
  const double s2 = fastest(rounds, [&] { springLoop(withDerivative, calls, true); });
  std::printf("spring law f(t, x, xdot), %ld evaluations\n| evaluation | ns |\n|---|---|\n", calls);
  std::printf("| value | %.2f |\n| value + central differences (5 calls) | %.2f |\n"
              "| value + user derivative | %.2f |\n\n",
              1e9 * s0 / calls, 1e9 * s1 / calls, 1e9 * s2 / calls);

  // 3. whole runs (50 s, outputs every 0.01 s), calls counted
  static std::atomic<long> count{0};
  const TimeLawPtr counted = makeUserTimeLaw([](double t) {
    count.fetch_add(1, std::memory_order_relaxed);
    return 0.0 + kA * std::sin(kW * t + 0.0);
  });
  count = 0;
  double rb = 1e300, ru = 1e300;
  for (int r = 0; r < rounds; ++r) {  // interleaved
    rb = std::min(rb, runPendulum(builtIn));
    ru = std::min(ru, runPendulum(counted));
  }
  const double perRun = static_cast<double>(count.load()) / rounds;
  std::printf("pendulum with a torque law, 50 s: runs, fastest of %d\n| law | run [ms] | law calls |\n|---|---|---|\n",
              rounds);
  std::printf("| built-in | %.3f | - |\n| user | %.3f | %.0f |\n", 1e3 * rb, 1e3 * ru, perRun);
  std::printf("| (user - built-in) / calls | %.1f ns | |\n\n", 1e9 * (ru - rb) / perRun);

  const SpringLawPtr countedSpring = makeSpringLaw([](double, double x, double xdot) {
    count.fetch_add(1, std::memory_order_relaxed);
    return 50.0 * (x - 1.0) + 0.8 * xdot;
  });
  count = 0;
  double sb = 1e300, su = 1e300;
  for (int r = 0; r < rounds; ++r) {
    sb = std::min(sb, runSlider(nullptr));
    su = std::min(su, runSlider(countedSpring));
  }
  const double springCalls = static_cast<double>(count.load()) / rounds;
  std::printf("slider on a spring-damper, 50 s: runs, fastest of %d\n| law | run [ms] | law calls |\n|---|---|---|\n",
              rounds);
  std::printf("| built-in linear | %.3f | - |\n| user (FD derivatives) | %.3f | %.0f |\n", 1e3 * sb, 1e3 * su,
              springCalls);
  std::printf("| (user - built-in) / calls | %.1f ns | |\n", 1e9 * (su - sb) / springCalls);
  return 0;
}
