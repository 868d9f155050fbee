// Benchmark: the rigid slider-crank of examples/slider_crank_rigid.json over one
// revolution. Work against precision at rtol 1e-6, 1e-8, 1e-10 (error against the
// closed form of source document 000, eqs. 30-32), the formulations and linear solvers
// side by side, and the cost of one residual and one Jacobian evaluation.
//
// Usage: bench_rigid_slider_crank [--repeat N] [--quick] [--csv FILE] [--out-dir DIR]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "benchmarks/bench_common.hpp"
#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "problems/reference_solutions.hpp"

using namespace flexmbd;
using flexmbd::bench::Clock;
using flexmbd::bench::median;
using flexmbd::bench::secondsSince;
using flexmbd::bench::timePerCall;

namespace {

const std::string kScene = std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json";

struct Row {
  std::string variant;
  double rtol = 0;
  long steps = 0, res = 0, jac = 0, setups = 0;
  double seconds = 0;     // median wall time of a whole run (initialisation included)
  double errX = 0, errV = 0, errA = 0;  // max relative error (x) / relative to amplitude
};

Row runOnce(double rtol, Formulation f, LinearSolverKind ls, bool fdJac, int repeat,
            const std::string& name) {
  Row row;
  row.variant = name;
  row.rtol = rtol;
  std::vector<double> times;
  for (int r = 0; r < repeat; ++r) {
    Scene scene = loadScene(kScene);
    SolverSettings st = scene.solver;
    st.rtol = rtol;
    st.atol = rtol * 1e-2;
    st.formulation = f;
    st.linearSolver = ls;
    st.finiteDifferenceJacobian = fdJac;
    st.progress = false;
    const int ix = scene.system.coordinateOffset(scene.system.findBody("slider"));
    double ex = 0, ev = 0, ea = 0;
    const double vScale = 1.5, aScale = 1.5;  // l1 w (1 + l1/l2), l1 w^2 (1 + l1/l2)
    const auto t0 = Clock::now();
    const SimulationSummary s = simulate(scene.system, st, [&](const OutputSample& o) {
      const auto ref = reference::sliderCrank(1.0, 2.0, o.t);
      ex = std::max(ex, std::abs(o.q[ix] - ref.x) / std::abs(ref.x));
      ev = std::max(ev, std::abs(o.v[ix] - ref.xd) / vScale);
      ea = std::max(ea, std::abs(o.a[ix] - ref.xdd) / aScale);
    });
    times.push_back(secondsSince(t0));
    if (!s.ok) std::fprintf(stderr, "%s rtol %g failed: %s\n", name.c_str(), rtol, s.message.c_str());
    row.steps = s.stats.steps;
    row.res = s.stats.residualEvals;
    row.jac = s.stats.jacobianEvals;
    row.setups = s.stats.linearSetups;
    row.errX = ex;
    row.errV = ev;
    row.errA = ea;
  }
  row.seconds = median(times);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Options opt("bench_rigid_slider_crank",
                     "Rigid slider-crank: precision, formulations, linear solvers, residual and Jacobian cost.", 5);
  opt.parse(argc, argv);
  if (opt.quick) opt.repeat = 1;
  const int repeat = opt.repeat;
  const std::string csvPath = opt.csvPath("bench_rigid_slider_crank.csv");
  std::vector<Row> rows;
  for (double rtol : {1e-6, 1e-8, 1e-10}) {
    rows.push_back(runOnce(rtol, Formulation::Ggl, LinearSolverKind::Dense, false, repeat, "ggl/dense/analytic"));
  }
  // Variants at rtol 1e-8, timed in the same run (report as ratios to the default).
  rows.push_back(runOnce(1e-8, Formulation::Ggl, LinearSolverKind::Klu, false, repeat, "ggl/klu/analytic"));
  rows.push_back(runOnce(1e-8, Formulation::Ggl, LinearSolverKind::Dense, true, repeat, "ggl/dense/fd-jacobian"));
  rows.push_back(runOnce(1e-8, Formulation::Index3, LinearSolverKind::Dense, false, repeat, "index3/dense/analytic"));
  rows.push_back(runOnce(1e-8, Formulation::Index1, LinearSolverKind::Dense, false, repeat, "index1/dense/analytic"));

  std::printf("Rigid slider-crank (l1 = 1, l2 = 2, 1 rad/s), one revolution, 60 outputs; atol = rtol/100\n");
  std::printf("errors: x relative; v, a relative to their amplitude (1.5); time: median of %d runs\n\n", repeat);
  std::printf("%-24s %7s %6s %6s %6s %6s %10s %9s %9s %9s %7s\n", "variant", "rtol", "steps", "res", "jac",
              "setup", "time [ms]", "err x", "err v", "err a", "ratio");
  const double base = rows[1].seconds;  // ggl/dense at 1e-8
  for (const Row& r : rows) {
    std::printf("%-24s %7.0e %6ld %6ld %6ld %6ld %10.3f %9.2e %9.2e %9.2e %7.2f\n", r.variant.c_str(), r.rtol,
                r.steps, r.res, r.jac, r.setups, 1e3 * r.seconds, r.errX, r.errV, r.errA,
                r.rtol == 1e-8 ? r.seconds / base : NAN);
  }

  // Dense LU against KLU on a small system: a 10-unknown pendulum released at 80 degrees,
  // 100 s at rtol 1e-8 (the basis of kDenseSizeLimit in integrators/ida_solver.hpp). IDA
  // named: auto takes radau5 here (eigenvalue 3.4 /s above the output Nyquist frequency;
  // its angle error after 100 s is 8e-5 rad against IDA's 1.2e-2).
  {
    const std::string pendulum = R"({"gravity": [0, -9.81],
      "bodies": [{"name": "bob", "type": "rigid", "mass": 2, "inertia": 0.05, "com": [0.8, 0], "angle": 1.4}],
      "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bob"], "points": [[0, 0], [0, 0]]}],
      "solver": {"t_end": 100, "output_step": 1, "integrator": "ida"}})";
    double t[2] = {0, 0};
    long steps[2] = {0, 0};
    int k = 0;
    for (LinearSolverKind ls : {LinearSolverKind::Dense, LinearSolverKind::Klu}) {
      std::vector<double> times;
      for (int r = 0; r < repeat; ++r) {
        Scene scene = parseSceneText(pendulum, "pendulum");
        scene.solver.linearSolver = ls;
        scene.solver.progress = false;
        const auto t0 = Clock::now();
        steps[k] = simulate(scene.system, scene.solver, nullptr).stats.steps;
        times.push_back(secondsSince(t0));
      }
      t[k++] = median(times);
    }
    std::printf("\nPendulum (DAE size 10), 100 s at rtol 1e-8: dense %.1f ms (%ld steps), KLU %.1f ms (%ld steps), "
                "KLU/dense %.2f\n", 1e3 * t[0], steps[0], 1e3 * t[1], steps[1], t[1] / t[0]);
  }

  // Cost of one residual and one Jacobian evaluation at a consistent state.
  Scene scene = loadScene(kScene);
  const System& sys = scene.system;
  const ConsistentState cs = computeConsistentState(sys, 0.3, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  VecX y, yp;
  dae.packState(cs.q, cs.v, cs.a, cs.lambda, y, yp);
  VecX F(dae.layout().size);
  std::vector<double> values(dae.pattern().nonZeros());
  MatX dense(dae.layout().size, dae.layout().size);
  const double tRes = timePerCall([&] { dae.residual(0.3, y.data(), yp.data(), F.data()); }, 2000);
  const double tJacSparse = timePerCall([&] {
    std::fill(values.begin(), values.end(), 0.0);
    JacobianSink sink = JacobianSink::sparse(values.data(), dae.pattern());
    dae.jacobian(0.3, y.data(), yp.data(), 100.0, sink);
  }, 2000);
  const double tJacDense = timePerCall([&] {
    dense.setZero();
    JacobianSink sink = JacobianSink::dense(dense.data(), dae.layout().size);
    dae.jacobian(0.3, y.data(), yp.data(), 100.0, sink);
  }, 2000);
  std::printf("\nDAE size %d, Jacobian non-zeros %lld\n", dae.layout().size,
              static_cast<long long>(dae.pattern().nonZeros()));
  std::printf("one residual evaluation:            %8.2f us\n", 1e6 * tRes);
  std::printf("one Jacobian evaluation (sparse):   %8.2f us  (%.1f residuals)\n", 1e6 * tJacSparse, tJacSparse / tRes);
  std::printf("one Jacobian evaluation (dense):    %8.2f us  (%.1f residuals)\n", 1e6 * tJacDense, tJacDense / tRes);

  std::ofstream csv(csvPath);
  csv << "variant,rtol,steps,residual_evals,jacobian_evals,linear_setups,seconds,err_x,err_v,err_a\n";
  for (const Row& r : rows) {
    csv << r.variant << "," << r.rtol << "," << r.steps << "," << r.res << "," << r.jac << "," << r.setups << ","
        << r.seconds << "," << r.errX << "," << r.errV << "," << r.errA << "\n";
  }
  csv << "# residual_us," << 1e6 * tRes << "\n# jacobian_sparse_us," << 1e6 * tJacSparse
      << "\n# jacobian_dense_us," << 1e6 * tJacDense << "\n";
  std::printf("\nCSV written to %s\n", csvPath.c_str());
  return 0;
}
