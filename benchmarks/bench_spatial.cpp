// Benchmark of the spatial models.
//
// (a) Work precision, rtol from --max-rtol (1e-4) to --min-rtol (1e-10) by decades,
//     atol = rtol / 100, GGL, IDA, automatic linear solver; CPU time of simulate()
//     (consistent initialisation and outputs included), median of --repeat runs:
//   free body   torque-free asymmetric body of tests/test_spatial_dynamics.cpp (m = 2,
//               J = diag(1, 2, 3), w0 = (1, 2, -1.5) rad/s body axes), 20 s; error of the
//               angular velocity |w - w_ref| / |w_ref| and of the orientation (angle of
//               A_ref^T A) at 20 s against the same model at --ref-rtol (1e-12); drifts:
//               max over the outputs of |E - E0| / E0 and |H - H0| / |H0| (H world axes)
//   heavy top   symmetric top on a spherical joint in steady precession (Goldstein eq.
//               5.74, the test's parameters), 2 s; max over the outputs of the tilt and
//               azimuth errors against the closed form [rad]
//   crank       spatial slider crank of the test (revolute, spherical, universal,
//               prismatic, joint angle driver; r = 0.15, L = 0.45, h = 0.1, 1 rev/s), 2 s;
//               max over the outputs of |x - s(theta)| [m] (closed form), and of the
//               velocity and acceleration errors
// (b) Cost of one residual and one Jacobian (DaeSystem::residual / jacobian with a scratch
//     of makeScratch(), Jacobian into JacobianSink::sparse of the DAE's pattern, cj = 100)
//     at the consistent state at t = 0.3 of the rigid slider crank of
//     examples/slider_crank_rigid.json (l1 = 1, l2 = 2, 1 rad/s, no gravity) and of the same
//     mechanism built of spatial bodies in the x-y plane (joint axes along world z, slider
//     along x): with revolute joints (as the planar model; 3 of its 21 equations are
//     redundant in space) and with a spherical joint at the crank pin and a universal
//     joint at the slider (18 independent equations). Rounds interleave the models; the
//     ratio spatial / planar is the median over the rounds of the ratio within a round.
//     DAE sizes of each, and one revolution of each model at rtol 1e-6, 1e-8, 1e-10
//     against the closed form (runs interleaved), with the planar model also with its
//     body frames at the centres of mass (as the spatial bodies have them).
//
// Usage: bench_spatial [--repeat N] [--rounds N] [--quick] [--min-rtol X] [--max-rtol X]
//                      [--ref-rtol X] [--skip-sweeps] [--profile planar|revolute|cardan]
//                      [--csv FILE] [--out-dir DIR]
// --profile runs only the evaluation loops of one in-plane model (for callgrind):
//   valgrind --tool=callgrind build/benchmarks/bench_spatial --profile cardan --rounds 1
#include <time.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "benchmarks/bench_common.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/dae_system.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"
#include "problems/reference_solutions.hpp"

using namespace flexmbd;
using flexmbd::bench::CsvWriter;
using flexmbd::bench::fmt;
using flexmbd::bench::median;
using flexmbd::bench::sci;

namespace {

constexpr double kGravity = 9.81;

double cpuNow() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

SolverSettings settings(double tEnd, double rtol, double outputStep) {
  SolverSettings st;
  st.rtol = rtol;
  st.atol = rtol * 1e-2;
  st.tEnd = tEnd;
  st.outputStep = outputStep;
  st.progress = false;
  return st;
}

Mat3 rotationX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }

/// Rotation angle of A_ref^T A [rad].
double orientationError(const Mat3& A, const Mat3& Aref) {
  const Mat3 R = Aref.transpose() * A;
  const Vec3 axis(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * axis.norm(), 0.5 * (R.trace() - 1.0));
}

// ---------------------------------------------------------------------------------------
// Models

/// Torque-free asymmetric body (tests/test_spatial_dynamics.cpp).
System freeBody() {
  System sys;
  RigidBody3dProperties p;
  p.mass = 2.0;
  p.inertia = Vec3(1.0, 2.0, 3.0).asDiagonal();
  FrameState3d s;
  s.orientation = rotationX(0.3);
  s.velocity = Vec3(0.1, -0.2, 0.3);
  s.angularVelocity = Vec3(1.0, 2.0, -1.5);
  sys.addBody(std::make_unique<RigidBody3d>("body", p, s));
  sys.finalize();
  return sys;
}

/// Heavy symmetric top in steady precession (the test's parameters).
struct Top {
  static constexpr double m = 1.5, l = 0.2, Ic = 0.01, I3 = 0.012, theta = 0.5, w3 = 100.0;
  static double precessionRate() {
    const double I1 = Ic + m * l * l;
    const double a = I1 * std::cos(theta), b = -I3 * w3, c = m * kGravity * l;
    return (-b - std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
  }
  static System build() {
    const double phid = precessionRate();
    System sys;
    sys.setGravity(Vec3(0.0, 0.0, -kGravity));
    RigidBody3dProperties p;
    p.mass = m;
    p.inertia = Vec3(Ic, Ic, I3).asDiagonal();
    FrameState3d s0;
    s0.orientation = rotationX(theta);
    s0.position = s0.orientation * Vec3(0.0, 0.0, l);
    const Vec3 wBody(0.0, phid * std::sin(theta), w3);
    s0.angularVelocity = wBody;
    s0.velocity = (s0.orientation * wBody).cross(s0.position);
    const BodyIndex top = sys.addBody(std::make_unique<RigidBody3d>("top", p, s0));
    JointFrame tip;
    tip.point = Vec3(0.0, 0.0, -l);
    sys.addConstraint(
        std::make_unique<SpatialJoint>("tip", SpatialJointType::Spherical, kGround, JointFrame{}, top, tip));
    sys.finalize();
    return sys;
  }
};

/// Spatial slider crank: crank of radius r about world z at w from th0; slider on a line
/// along x at height h; rod of length L. Closed form (tests/test_spatial_dynamics.cpp):
/// s(th) = r cos th + sqrt(L^2 - h^2 - r^2 sin^2 th).
struct CrankGeometry {
  double r, L, h, w, th0;
  double D(double th) const { return std::sqrt(L * L - h * h - r * r * std::sin(th) * std::sin(th)); }
  double s(double th) const { return r * std::cos(th) + D(th); }
  double ds(double th) const { return -r * std::sin(th) - r * r * std::sin(th) * std::cos(th) / D(th); }
  double dds(double th) const {
    const double sc = std::sin(th) * std::cos(th), d = D(th);
    return -r * std::cos(th) - r * r * std::cos(2.0 * th) / d - std::pow(r, 4) * sc * sc / (d * d * d);
  }
};

RigidBody3dProperties props(double m, const Vec3& J) {
  RigidBody3dProperties p;
  p.mass = m;
  p.inertia = J.asDiagonal();
  return p;
}

Vec3 boxInertia(double m, const Vec3& size) {
  return m / 12.0 *
         Vec3(size.y() * size.y() + size.z() * size.z(), size.x() * size.x() + size.z() * size.z(),
              size.x() * size.x() + size.y() * size.y());
}

struct SpatialCrank {
  System sys;
  BodyIndex crank, rod, slider;
};

/// revolutes: revolute joints at the crank pin and the slider (the planar mechanism's
/// joints; needs h = 0, and 3 of the 21 equations are then redundant); else a spherical
/// joint at the crank pin and a universal joint at the slider (as the test).
SpatialCrank buildCrank(const CrankGeometry& C, const RigidBody3dProperties& pc, const RigidBody3dProperties& pr,
                        const RigidBody3dProperties& ps, const Vec3& gravity, bool revolutes) {
  SpatialCrank m;
  System& sys = m.sys;
  sys.setGravity(gravity);
  // crank: body x axis along the crank, centre of mass at mid-length
  FrameState3d crank0;
  crank0.orientation = Eigen::AngleAxisd(C.th0, Vec3::UnitZ()).toRotationMatrix();
  crank0.position = crank0.orientation * Vec3(C.r / 2, 0.0, 0.0);
  m.crank = sys.addBody(std::make_unique<RigidBody3d>("crank", pc, crank0));
  // rod: body x axis from the crank pin P to the slider S, centre of mass at mid-length
  const Vec3 P = C.r * Vec3(std::cos(C.th0), std::sin(C.th0), 0.0), S(C.s(C.th0), 0.0, C.h);
  const Vec3 e1 = (S - P).normalized(), cross = e1.cross(Vec3::UnitY()).normalized();
  FrameState3d rod0;
  rod0.orientation.col(0) = e1;
  rod0.orientation.col(1) = cross.cross(e1);
  rod0.orientation.col(2) = cross;
  rod0.position = 0.5 * (P + S);
  m.rod = sys.addBody(std::make_unique<RigidBody3d>("rod", pr, rod0));
  FrameState3d slider0;
  slider0.position = S;
  m.slider = sys.addBody(std::make_unique<RigidBody3d>("slider", ps, slider0));
  JointFrame origin, crankAxis, crankPin, rodEnd, rodStart, sliderCross, rail;
  crankAxis.point = Vec3(-C.r / 2, 0.0, 0.0);
  crankPin.point = Vec3(C.r / 2, 0.0, 0.0);
  rodStart.point = Vec3(-C.L / 2, 0.0, 0.0);
  rodEnd.point = Vec3(C.L / 2, 0.0, 0.0);
  rail.axes.col(0) = Vec3::UnitY();  // prismatic along frame z = world x
  rail.axes.col(1) = Vec3::UnitZ();
  rail.axes.col(2) = Vec3::UnitX();
  rail.point = Vec3(0.0, 0.0, C.h);
  JointFrame railOnSlider = rail;
  railOnSlider.point = Vec3::Zero();
  sys.addConstraint(
      std::make_unique<SpatialJoint>("bearing", SpatialJointType::Revolute, kGround, origin, m.crank, crankAxis));
  if (revolutes) {
    // joint axes: the frames' z axes, world z for both bodies (in the plane, rod axes = world axes up to a turn about
    // z)
    sys.addConstraint(
        std::make_unique<SpatialJoint>("pin", SpatialJointType::Revolute, m.crank, crankPin, m.rod, rodStart));
    JointFrame sliderPin;
    sys.addConstraint(
        std::make_unique<SpatialJoint>("wrist", SpatialJointType::Revolute, m.slider, sliderPin, m.rod, rodEnd));
  } else {
    // the cross: frame x on the slider along world y, frame y on the rod along `cross`
    sliderCross.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    rodEnd.axes.col(0) = Vec3::UnitY();
    rodEnd.axes.col(1) = Vec3::UnitZ();
    rodEnd.axes.col(2) = Vec3::UnitX();
    sys.addConstraint(
        std::make_unique<SpatialJoint>("pin", SpatialJointType::Spherical, m.crank, crankPin, m.rod, rodStart));
    sys.addConstraint(
        std::make_unique<SpatialJoint>("cardan", SpatialJointType::Universal, m.slider, sliderCross, m.rod, rodEnd));
  }
  sys.addConstraint(
      std::make_unique<SpatialJoint>("rail", SpatialJointType::Prismatic, kGround, rail, m.slider, railOnSlider));
  sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, origin, m.crank, crankAxis,
                                                              makeConstantSpeedLaw(C.w, C.th0)));
  sys.finalize();
  return m;
}

/// The test's spatial slider crank (1 rev/s, rail 0.1 m above the crank plane).
const CrankGeometry kTestCrank{0.15, 0.45, 0.1, 2.0 * M_PI, 0.3};
SpatialCrank testCrank() {
  return buildCrank(kTestCrank, props(1.0, boxInertia(1.0, Vec3(kTestCrank.r, 0.02, 0.02))),
                    props(0.5, boxInertia(0.5, Vec3(kTestCrank.L, 0.02, 0.02))),
                    props(2.0, boxInertia(2.0, Vec3(0.1, 0.05, 0.05))), Vec3(0.0, 0.0, -kGravity), false);
}

/// The planar rigid slider crank (examples/slider_crank_rigid.json) of spatial bodies:
/// l1 = 1, l2 = 2, 1 rad/s from 0, no gravity; masses and the in-plane moments of inertia
/// (about z) of the planar model, the others chosen (a thin crank and rod along their x
/// axes, a cube-like slider).
const CrankGeometry kPlaneCrank{1.0, 2.0, 0.0, 1.0, 0.0};
SpatialCrank planeCrank(bool revolutes) {
  return buildCrank(kPlaneCrank, props(1.0, Vec3(0.001, 0.1, 0.1)), props(1.0, Vec3(0.001, 0.4, 0.4)),
                    props(0.5, Vec3(0.01, 0.01, 0.01)), Vec3::Zero(), revolutes);
}

// ---------------------------------------------------------------------------------------
// (a) work precision

struct WpRow {
  double rtol = 0;
  double cpu = 0;  // median CPU seconds of simulate()
  long steps = 0, res = 0, jac = 0, etf = 0, ncf = 0;
  bool ok = true;
  std::string message;
  double e1 = NAN, e2 = NAN, e3 = NAN, e4 = NAN;  // model-specific errors
};

/// Runs `run` (one simulation returning a row without time) `repeat` times; median CPU.
template <class Run>
WpRow timed(double rtol, int repeat, Run&& run) {
  std::vector<double> t;
  WpRow row;
  for (int k = 0; k < repeat; ++k) {
    const double c0 = cpuNow();
    row = run(rtol);
    t.push_back(cpuNow() - c0);
    if (!row.ok) break;
  }
  row.rtol = rtol;
  row.cpu = median(t);
  return row;
}

void fillStats(WpRow& row, const SimulationSummary& s) {
  row.steps = s.stats.steps;
  row.res = s.stats.residualEvals;
  row.jac = s.stats.jacobianEvals;
  row.etf = s.stats.errorTestFailures;
  row.ncf = s.stats.nonlinearConvFailures;
  row.ok = s.ok;
  row.message = s.message;
}

struct FreeBodyEnd {
  Vec3 w;
  Mat3 A;
};

WpRow runFreeBody(double rtol, FreeBodyEnd* end, const FreeBodyEnd* ref) {
  const System sys = freeBody();
  const auto& body = dynamic_cast<const RigidBody3d&>(sys.body(BodyIndex(1)));
  const int qo = sys.coordinateOffset(BodyIndex(1)), vo = sys.velocityOffset(BodyIndex(1));
  double E0 = NAN, dE = 0, dH = 0;
  Vec3 H0 = Vec3::Zero();
  FreeBodyEnd last;
  const SimulationSummary s = simulate(sys, settings(20.0, rtol, 0.05), [&](const OutputSample& o) {
    const Mat3 A = RigidBody3d::rotationOf(o.q.segment(qo, 7));
    const Vec3 w = o.v.segment<3>(vo + 3);
    const double E = kineticEnergy(sys, o.q, o.v);
    const Vec3 H = A * (body.inertia() * w);
    if (std::isnan(E0)) {
      E0 = E;
      H0 = H;
    }
    dE = std::max(dE, std::abs(E - E0) / E0);
    dH = std::max(dH, (H - H0).norm() / H0.norm());
    last = {w, A};
  });
  WpRow row;
  fillStats(row, s);
  if (end) *end = last;
  if (ref) {
    row.e1 = (last.w - ref->w).norm() / ref->w.norm();
    row.e2 = orientationError(last.A, ref->A);
  }
  row.e3 = dE;
  row.e4 = dH;
  return row;
}

WpRow runTop(double rtol) {
  const System sys = Top::build();
  const double phid = Top::precessionRate();
  const int qo = sys.coordinateOffset(BodyIndex(1));
  double tilt = 0, azimuth = 0;
  const SimulationSummary s = simulate(sys, settings(2.0, rtol, 0.01), [&](const OutputSample& o) {
    const Vec3 axis = RigidBody3d::rotationOf(o.q.segment(qo, 7)).col(2);
    tilt = std::max(tilt, std::abs(std::acos(std::clamp(axis.z(), -1.0, 1.0)) - Top::theta));
    const double az = std::atan2(axis.y(), axis.x());  // -pi/2 at t = 0
    azimuth = std::max(azimuth, std::abs(std::remainder(az - (-M_PI / 2 + phid * o.t), 2 * M_PI)));
  });
  WpRow row;
  fillStats(row, s);
  row.e1 = tilt;
  row.e2 = azimuth;
  return row;
}

WpRow runCrank(double rtol) {
  const SpatialCrank m = testCrank();
  const CrankGeometry& C = kTestCrank;
  const int xs = m.sys.coordinateOffset(m.slider), vs = m.sys.velocityOffset(m.slider);
  double ex = 0, ev = 0, ea = 0;
  const SimulationSummary s = simulate(m.sys, settings(2.0, rtol, 0.01), [&](const OutputSample& o) {
    const double th = C.th0 + C.w * o.t;
    ex = std::max(ex, std::abs(o.q[xs] - C.s(th)));
    ev = std::max(ev, std::abs(o.v[vs] - C.ds(th) * C.w));
    ea = std::max(ea, std::abs(o.a[vs] - C.dds(th) * C.w * C.w));
  });
  WpRow row;
  fillStats(row, s);
  row.e1 = ex;
  row.e2 = ev;
  row.e3 = ea;
  return row;
}

void printWp(const char* title, const char* h1, const char* h2, const char* h3, const char* h4,
             const std::vector<WpRow>& rows, CsvWriter& csv, const std::string& model) {
  std::printf("\n%s\n", title);
  std::printf("%7s %10s %7s %7s %6s %5s %5s %10s %10s", "rtol", "CPU [ms]", "steps", "res", "jac", "etf", "ncf", h1,
              h2);
  if (h3) std::printf(" %10s", h3);
  if (h4) std::printf(" %10s", h4);
  std::printf("\n");
  for (const WpRow& r : rows) {
    std::printf("%7.0e %10.2f %7ld %7ld %6ld %5ld %5ld %10.2e %10.2e", r.rtol, 1e3 * r.cpu, r.steps, r.res, r.jac,
                r.etf, r.ncf, r.e1, r.e2);
    if (h3) std::printf(" %10.2e", r.e3);
    if (h4) std::printf(" %10.2e", r.e4);
    if (!r.ok) std::printf("  FAILED: %s", r.message.c_str());
    std::printf("\n");
    csv.row({model, fmt(r.rtol, "%.0e"), fmt(r.cpu), std::to_string(r.steps), std::to_string(r.res),
             std::to_string(r.jac), std::to_string(r.etf), std::to_string(r.ncf), sci(r.e1), sci(r.e2), sci(r.e3),
             sci(r.e4), r.ok ? "1" : "0"});
  }
}

// ---------------------------------------------------------------------------------------
// (b) cost per evaluation

struct EvalModel {
  std::string name;
  std::unique_ptr<Scene> scene;         // planar model
  std::unique_ptr<SpatialCrank> crank;  // spatial model
  std::unique_ptr<DaeSystem> dae;
  std::unique_ptr<DaeScratch> scratch;
  VecX y, yp, F;
  std::vector<double> values;
  std::vector<double> tRes, tJac;  // per round [s]
  double constraintResidual = 0;   // max |F| over the constraint rows at the state
  const System& sys() const { return scene ? scene->system : crank->sys; }
};

constexpr double kEvalTime = 0.3, kCj = 100.0;

void prepare(EvalModel& m, const VecX& q, const VecX& v, const VecX& a, const VecX& lambda) {
  m.dae = std::make_unique<DaeSystem>(m.sys(), Formulation::Ggl);
  m.dae->packState(q, v, a, lambda, m.y, m.yp);
  m.scratch = m.dae->makeScratch();
  m.F.setZero(m.dae->size());
  m.values.assign(m.dae->pattern().nonZeros(), 0.0);
  m.dae->residual(kEvalTime, m.y.data(), m.yp.data(), m.F.data(), *m.scratch);
  const DaeLayout& L = m.dae->layout();
  m.constraintResidual = m.F.segment(L.lambda, L.size - L.lambda).lpNorm<Eigen::Infinity>();
}

double cpuPerCall(const std::function<void()>& fn, int n) {
  const double c0 = cpuNow();
  for (int i = 0; i < n; ++i) fn();
  return (cpuNow() - c0) / n;
}

/// One revolution (60 outputs): CPU time, counters, max |x - x_exact| relative.
struct RevolutionRun {
  double cpu = 0;
  long steps = 0, res = 0, jac = 0, etf = 0, ncf = 0;
  double err = 0;
  std::vector<double> times;
  bool ok = true;
  std::string message;
};

template <class Build>
RevolutionRun revolution(Build&& build, double rtol, int repeat) {
  RevolutionRun out;
  std::vector<double> t;
  for (int k = 0; k < repeat; ++k) {
    try {
      const auto built = build();
      const System& sys = *built.first;
      const int xs = built.second;
      double err = 0;
      const double c0 = cpuNow();
      const SimulationSummary s = simulate(sys, settings(2 * M_PI, rtol, 2 * M_PI / 60), [&](const OutputSample& o) {
        const auto ref = reference::sliderCrank(1.0, 2.0, o.t);
        err = std::max(err, std::abs(o.q[xs] - ref.x) / std::abs(ref.x));
      });
      t.push_back(cpuNow() - c0);
      out.steps = s.stats.steps;
      out.res = s.stats.residualEvals;
      out.jac = s.stats.jacobianEvals;
      out.etf = s.stats.errorTestFailures;
      out.ncf = s.stats.nonlinearConvFailures;
      out.err = err;
      out.ok = s.ok;
      out.message = s.message;
    } catch (const std::exception& e) {
      out.ok = false;
      out.message = e.what();
      break;
    }
  }
  out.cpu = median(t);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Options opt("bench_spatial",
                     "Spatial models: work precision (free body, heavy top, slider crank) and the cost of a residual "
                     "and a Jacobian against the planar slider crank.",
                     3);
  double minRtol = 1e-10, maxRtol = 1e-4, refRtol = 1e-12;
  int rounds = 9;
  opt.addDouble("--min-rtol", "tightest rtol of the sweeps (default 1e-10)", &minRtol);
  opt.addDouble("--max-rtol", "loosest rtol of the sweeps (default 1e-4)", &maxRtol);
  opt.addDouble("--ref-rtol", "rtol of the free body's reference (default 1e-12)", &refRtol);
  opt.addInt("--rounds", "interleaved rounds of the evaluation timings (default 9)", &rounds);
  bool skipSweeps = false;
  std::string profile;
  opt.flag("--skip-sweeps", "only the evaluation costs and the in-plane runs (part b)", &skipSweeps);
  opt.addString("--profile",
                "planar|revolute|cardan: only the residual and Jacobian loops of that in-plane model, "
                "--rounds times, no output (for callgrind)",
                &profile);
  opt.parse(argc, argv);
  if (opt.quick) {
    opt.repeat = 1;
    minRtol = std::max(minRtol, 1e-6);
    rounds = 3;
  }
  std::vector<double> rtols;
  for (double r = maxRtol; r >= minRtol * 0.999; r /= 10) rtols.push_back(r);

  CsvWriter csv(opt.csvPath("bench_spatial.csv"),
                {"model", "rtol", "cpu_s", "steps", "residual_evals", "jacobian_evals", "error_test_failures",
                 "convergence_failures", "e1", "e2", "e3", "e4", "ok"});
  csv.comment(
      "free_body: e1 = |w - w_ref|/|w_ref| at 20 s, e2 = orientation error [rad] at 20 s, e3 = energy drift, e4 = "
      "angular momentum drift");
  csv.comment("heavy_top: e1 = max tilt error [rad], e2 = max azimuth error [rad]");
  csv.comment("slider_crank: e1 = max |x - s| [m], e2 = max |x' - s'| [m/s], e3 = max |x'' - s''| [m/s^2]");

  if (!profile.empty()) skipSweeps = true;
  if (!skipSweeps) {
    std::printf(
        "Spatial models, GGL, IDA, atol = rtol/100; CPU time of simulate() (initialisation and outputs\n"
        "included), median of %d runs\n",
        opt.repeat);

    // --- free body -------------------------------------------------------------------
    {
      FreeBodyEnd ref;
      const WpRow r = runFreeBody(refRtol, &ref, nullptr);
      std::vector<WpRow> rows;
      for (double rtol : rtols)
        rows.push_back(timed(rtol, opt.repeat, [&](double rt) { return runFreeBody(rt, nullptr, &ref); }));
      char title[512];
      std::snprintf(title, sizeof title,
                    "Torque-free asymmetric body, J = (1, 2, 3), w0 = (1, 2, -1.5) rad/s, 20 s, outputs every 0.05 s.\n"
                    "err w, err A: angular velocity (relative) and orientation [rad] at 20 s against rtol %.0e "
                    "(%ld steps%s);\ndE, dH: max relative change of the energy and of the angular momentum (world)",
                    refRtol, r.steps, r.ok ? "" : ", FAILED");
      printWp(title, "err w", "err A", "dE", "dH", rows, csv, "free_body");
      std::printf("%7s %10s %7ld %7ld %6ld %5ld %5ld %10s %10s %10.2e %10.2e   (reference)\n",
                  fmt(refRtol, "%.0e").c_str(), "", r.steps, r.res, r.jac, r.etf, r.ncf, "", "", r.e3, r.e4);
    }
    // --- heavy top -------------------------------------------------------------------
    {
      std::vector<WpRow> rows;
      for (double rtol : rtols) rows.push_back(timed(rtol, opt.repeat, runTop));
      rows.push_back(timed(refRtol, 1, runTop));
      char title[512];
      std::snprintf(title, sizeof title,
                    "Heavy symmetric top in steady precession (m = 1.5, l = 0.2, tilt 0.5 rad, spin 100 rad/s,\n"
                    "precession %.4f rad/s), 2 s, outputs every 0.01 s; max error against the closed form [rad]; the "
                    "last row once",
                    Top::precessionRate());
      printWp(title, "tilt", "azimuth", nullptr, nullptr, rows, csv, "heavy_top");
    }
    // --- spatial slider crank --------------------------------------------------------
    {
      std::vector<WpRow> rows;
      for (double rtol : rtols) rows.push_back(timed(rtol, opt.repeat, runCrank));
      rows.push_back(timed(refRtol, 1, runCrank));
      printWp(
          "Spatial slider crank (revolute, spherical, universal, prismatic, angle driver; r = 0.15, L = 0.45,\n"
          "h = 0.1 m, 1 rev/s), 2 s, outputs every 0.01 s; max error of the slider against the closed form:\n"
          "x [m], x' [m/s], x'' [m/s^2]; the last row once",
          "err x", "err x'", "err x''", nullptr, rows, csv, "slider_crank");
    }
  }  // !skipSweeps

  // --- (b) cost per evaluation -------------------------------------------------------
  std::vector<EvalModel> models(3);
  models[0].name = "planar: 3 revolute + prismatic + body angle driver";
  models[0].scene =
      std::make_unique<Scene>(loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json"));
  {
    const System& sys = models[0].sys();
    const ConsistentState cs =
        computeConsistentState(sys, kEvalTime, sys.initialCoordinates(), sys.initialVelocities());
    prepare(models[0], cs.q, cs.v, cs.a, cs.lambda);
  }
  models[1].name = "spatial: 3 revolute + prismatic + angle driver";
  models[1].crank = std::make_unique<SpatialCrank>(planeCrank(true));
  models[2].name = "spatial: revolute + spherical + universal + prismatic + driver";
  models[2].crank = std::make_unique<SpatialCrank>(planeCrank(false));
  {
    // The consistent state of the non-redundant model; the revolute model has the same
    // bodies and coordinates, its multipliers are the minimum-norm ones.
    const System& sys = models[2].sys();
    const ConsistentState cs =
        computeConsistentState(sys, kEvalTime, sys.initialCoordinates(), sys.initialVelocities());
    prepare(models[2], cs.q, cs.v, cs.a, cs.lambda);
    VecX a, lambda;
    computeAccelerations(models[1].sys(), kEvalTime, cs.q, cs.v, a, lambda);
    prepare(models[1], cs.q, cs.v, a, lambda);
  }
  const int nRes = opt.quick ? 2000 : 20000, nJac = opt.quick ? 500 : 5000;
  if (!profile.empty()) {
    const int k = profile == "planar" ? 0 : profile == "revolute" ? 1 : profile == "cardan" ? 2 : -1;
    if (k < 0) {
      std::fprintf(stderr, "bench_spatial: --profile planar|revolute|cardan\n");
      return 2;
    }
    EvalModel& m = models[k];
    for (int round = 0; round < rounds; ++round) {
      for (int i = 0; i < nRes; ++i) m.dae->residual(kEvalTime, m.y.data(), m.yp.data(), m.F.data(), *m.scratch);
      for (int i = 0; i < nJac; ++i) {
        std::fill(m.values.begin(), m.values.end(), 0.0);
        JacobianSink sink = JacobianSink::sparse(m.values.data(), m.dae->pattern());
        m.dae->jacobian(kEvalTime, m.y.data(), m.yp.data(), kCj, sink, *m.scratch);
      }
    }
    return 0;
  }
  for (EvalModel& m : models) {  // warm-up
    cpuPerCall([&] { m.dae->residual(kEvalTime, m.y.data(), m.yp.data(), m.F.data(), *m.scratch); }, nRes / 10);
  }
  for (int round = 0; round < rounds; ++round) {
    for (EvalModel& m : models) {
      m.tRes.push_back(
          cpuPerCall([&] { m.dae->residual(kEvalTime, m.y.data(), m.yp.data(), m.F.data(), *m.scratch); }, nRes));
      m.tJac.push_back(cpuPerCall(
          [&] {
            std::fill(m.values.begin(), m.values.end(), 0.0);
            JacobianSink sink = JacobianSink::sparse(m.values.data(), m.dae->pattern());
            m.dae->jacobian(kEvalTime, m.y.data(), m.yp.data(), kCj, sink, *m.scratch);
          },
          nJac));
    }
  }
  std::printf(
      "\nOne residual and one Jacobian (sparse, into the DAE's pattern) of the slider crank l1 = 1, l2 = 2\n"
      "in the x-y plane, GGL, at the consistent state at t = %.1f; scratch of makeScratch(); CPU time,\n"
      "median of %d interleaved rounds (%d residuals, %d Jacobians per round and model); ratios: median\n"
      "over the rounds of spatial / planar within the round\n\n",
      kEvalTime, rounds, nRes, nJac);
  std::printf("%-62s %4s %4s %4s %5s %6s %8s %8s %8s %9s %9s %9s\n", "model", "nq", "nv", "m", "size", "nnz", "max|g|",
              "res [us]", "jac [us]", "jac/res", "res ratio", "jac ratio");
  CsvWriter ecsv(
      opt.csvPath("bench_spatial_eval.csv", false),
      {"model", "nq", "nv", "m", "dae_size", "nnz", "residual_us", "jacobian_us", "residual_ratio", "jacobian_ratio"});
  for (const EvalModel& m : models) {
    std::vector<double> rr, rj;
    for (int k = 0; k < rounds; ++k) {
      rr.push_back(m.tRes[k] / models[0].tRes[k]);
      rj.push_back(m.tJac[k] / models[0].tJac[k]);
    }
    const DaeLayout& L = m.dae->layout();
    const double tr = median(m.tRes), tj = median(m.tJac);
    std::printf("%-62s %4d %4d %4d %5d %6lld %8.1e %8.2f %8.2f %9.2f %9.2f %9.2f\n", m.name.c_str(), L.nq, L.nv, L.m,
                L.size, static_cast<long long>(m.dae->pattern().nonZeros()), m.constraintResidual, 1e6 * tr, 1e6 * tj,
                tj / tr, median(rr), median(rj));
    ecsv.row({m.name, std::to_string(L.nq), std::to_string(L.nv), std::to_string(L.m), std::to_string(L.size),
              std::to_string(m.dae->pattern().nonZeros()), fmt(1e6 * tr), fmt(1e6 * tj), fmt(median(rr), "%.3f"),
              fmt(median(rj), "%.3f")});
  }
  std::printf("max|g|: largest |F| of the constraint rows (F_g, F_gv) at the state (the same state for all three)\n");

  // one revolution of each (the same mechanism: the planar closed form)
  {
    std::printf(
        "\nOne revolution (60 outputs), CPU time of simulate(), median of %d runs; err x: max relative\n"
        "error of the slider against the closed form of the planar slider crank; ratio: CPU time / planar at\n"
        "the same rtol\n\n",
        opt.repeat);
    std::printf("%-62s %6s %9s %6s %6s %5s %5s %5s %10s %7s\n", "model", "rtol", "CPU [ms]", "steps", "res", "jac",
                "etf", "ncf", "err x", "ratio");
    auto planarScene = [] {
      auto scene =
          std::make_shared<Scene>(loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json"));
      const System& s = scene->system;
      return std::make_pair(std::shared_ptr<const System>(scene, &s), s.coordinateOffset(s.findBody("slider")));
    };
    // The planar model with its body frames at the centres of mass (as the spatial bodies):
    // its crank coordinates are then periodic in t, as the spatial ones, not (0, 0, t).
    auto planarComScene = [] {
      const std::string text = R"({"gravity": [0, 0],
        "bodies": [
          {"name": "crank", "type": "rigid", "mass": 1.0, "inertia": 0.1, "com": [0, 0], "position": [0.5, 0], "angle": 0},
          {"name": "rod", "type": "rigid", "mass": 1.0, "inertia": 0.4, "com": [0, 0], "position": [2, 0], "angle": 0},
          {"name": "slider", "type": "rigid", "mass": 0.5, "inertia": 0.01, "com": [0, 0], "position": [3, 0], "angle": 0}],
        "joints": [
          {"name": "O1", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], [-0.5, 0]]},
          {"name": "O2", "type": "revolute", "bodies": ["crank", "rod"], "points": [[0.5, 0], [-1, 0]]},
          {"name": "O3", "type": "revolute", "bodies": ["rod", "slider"], "points": [[1, 0], [0, 0]]},
          {"name": "P", "type": "prismatic", "bodies": ["ground", "slider"], "points": [[0, 0], [0, 0]], "axis": [1, 0]}],
        "drivers": [{"name": "motor", "type": "body_angle", "body": "crank", "law": {"type": "constant_speed", "speed": 1.0}}],
        "solver": {"t_end": 6.283185307179586, "output_step": 0.10471975511965977}})";
      auto scene = std::make_shared<Scene>(parseSceneText(text, "planar slider crank, frames at the centres of mass"));
      const System& s = scene->system;
      return std::make_pair(std::shared_ptr<const System>(scene, &s), s.coordinateOffset(s.findBody("slider")));
    };
    auto spatialScene = [](bool revolutes) {
      return [revolutes] {
        auto m = std::make_shared<SpatialCrank>(planeCrank(revolutes));
        return std::make_pair(std::shared_ptr<const System>(m, &m->sys), m->sys.coordinateOffset(m->slider));
      };
    };
    CsvWriter rcsv(opt.csvPath("bench_spatial_in_plane.csv", false),
                   {"model", "rtol", "cpu_s", "steps", "residual_evals", "jacobian_evals", "err_x", "ok"});
    const std::vector<double> revRtols =
        opt.quick ? std::vector<double>{1e-6, 1e-8} : std::vector<double>{1e-6, 1e-8, 1e-10};
    for (double rtol : revRtols) {
      RevolutionRun runs[4];
      // interleaved: planar, spatial (revolutes), spatial (cardan), planar (frames at the
      // centres of mass), repeated
      for (int r = 0; r < opt.repeat; ++r) {
        const RevolutionRun a = revolution(planarScene, rtol, 1), b = revolution(spatialScene(true), rtol, 1),
                            c = revolution(spatialScene(false), rtol, 1), d = revolution(planarComScene, rtol, 1);
        const RevolutionRun* now[4] = {&a, &b, &c, &d};
        for (int k = 0; k < 4; ++k) {
          if (r == 0) {
            runs[k] = *now[k];
            runs[k].cpu = 0;
          }
          runs[k].times.push_back(now[k]->cpu);
        }
      }
      for (int k = 0; k < 4; ++k) runs[k].cpu = median(runs[k].times);
      for (int k : {0, 3, 1, 2}) {
        const RevolutionRun& r = runs[k];
        const std::string name = k < 3 ? models[k].name : "planar: body frames at the centres of mass";
        if (r.ok) {
          std::printf("%-62s %6.0e %9.2f %6ld %6ld %5ld %5ld %5ld %10.2e %7.2f\n", name.c_str(), rtol, 1e3 * r.cpu,
                      r.steps, r.res, r.jac, r.etf, r.ncf, r.err, r.cpu / runs[0].cpu);
        } else {
          std::string msg = r.message;
          const size_t cut = msg.find(" defined before");
          if (cut != std::string::npos) msg = msg.substr(0, cut + 15);
          std::printf("%-62s %6.0e fails: %s\n", name.c_str(), rtol, msg.c_str());
        }
        rcsv.row({name, fmt(rtol, "%.0e"), fmt(r.cpu), std::to_string(r.steps), std::to_string(r.res),
                  std::to_string(r.jac), sci(r.err), r.ok ? "1" : "0"});
      }
    }
  }
  std::printf("\nCSV written to %s, %s and bench_spatial_in_plane.csv\n", csv.path().c_str(), ecsv.path().c_str());
  return 0;
}
