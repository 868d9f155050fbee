// The benchmark models, shared by the benchmark binaries: each with what is measured
// at its checkpoints (world positions), its characteristic length and, where there is
// one, the closed-form solution.
//
// Models (scene groups):
//   rigid_slider_crank  examples/slider_crank_rigid.json: l1 = 1, l2 = 2, 1 rad/s, one revolution
//   elastic_1rev        examples/slider_crank_elastic.json, 8 elements, one revolution (0.0419 s)
//   elastic_5rev        the same, five revolutions (0.209 s)
//   free_beam           free-free steel beam 0.3 m (8 elements, mean-axis frame; nodal and 3
//                       modes) flying (1, 0.5) m/s and spinning at 150 rad/s, released bent in
//                       its first free-free mode (1 mm at the ends), no gravity; one spin
//                       revolution (0.0419 s)
//   pendulum            physical pendulum of tests/test_pendulum.cpp (m = 2, I_com = 0.05,
//                       L = 0.8, g = 9.81) released at rest at 170 degrees; two periods
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "core/system_evaluation.hpp"
#include "integrators/initial_conditions.hpp"
#include "integrators/klu_ordering.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "problems/ffr_test_models.hpp"
#include "benchmarks/bench_common.hpp"
#include "problems/reference_solutions.hpp"

namespace flexmbd::bench {

/// What a model is measured by at one output time.
struct Probe {
  std::vector<double> positions;  ///< world coordinates [m], compared relative to the length
  double deflection = NAN;        ///< elastic slider-crank: rod midpoint transverse deflection
  double energy = NAN;            ///< conservative models: total energy
  Vec2 momentum = Vec2::Zero();   ///< free beam: linear momentum
  double angularMomentum = NAN;   ///< free beam: about the world origin
};

/// A model of a scene group, ready to build at any tolerance.
struct BenchModel {
  std::string group;       ///< scene group (rigid_slider_crank, elastic_1rev, ...)
  std::string model;       ///< rigid, nodal, 2 modes, 4 modes
  int elements = 0;        ///< beam elements (flexible models)
  int modes = 0;           ///< 0: nodal
  double span = 0;         ///< simulated time [s]
  int checkpoints = 8;     ///< outputs at span k / checkpoints, k = 1..checkpoints
  double length = 1;       ///< characteristic length [m] the position errors are divided by
  std::string positionsDoc;
  /// The scene with the rtol/atol given (output step = span / checkpoints).
  std::function<Scene(double rtol, double atol)> build;
  /// Measured quantities at an output (the scene it came from).
  std::function<Probe(const Scene&, const OutputSample&)> probe;
  /// Closed-form positions at time t, or empty: reference by the engine at a tight rtol.
  std::function<std::vector<double>(double t)> exact;
};

/// Rule tying atol to rtol in all benchmarks: atol = rtol / 100 (positions in m and
/// velocities in m/s; the models' lengths are 0.15 m to 2 m).
inline double atolFor(double rtol) { return 1e-2 * rtol; }

/// The run settings every sweep point shares: tolerances, span, one output per checkpoint.
inline void setRun(SolverSettings& solver, double rtol, double atol, double span, int checkpoints) {
  solver.rtol = rtol;
  solver.atol = atol;
  solver.tEnd = span;
  solver.outputStep = span / checkpoints;
  solver.progress = false;
}

inline std::string sourcePath(const std::string& rel) { return std::string(FLEXMBD_SOURCE_DIR) + "/" + rel; }

/// A run timed in two parts: the set-up (consistent state, DAE pattern, up to the output at
/// t_start) and the integration after it, both process CPU time [s].
struct TimedRun {
  SimulationSummary summary;
  double setup = 0.0, integration = 0.0;
};
inline TimedRun timedSimulate(const System& sys, const SolverSettings& settings) {
  TimedRun r;
  const double c0 = cpuSeconds();
  double started = NAN;  // CPU time at the first output
  r.summary = simulate(sys, settings, [&](const OutputSample&) {
    if (std::isnan(started)) started = cpuSeconds();
  });
  const double end = cpuSeconds();
  r.setup = started - c0;
  r.integration = end - started;
  return r;
}

/// nnz(L + U) of the GGL iteration matrix at the consistent initial state (cj of the
/// engine's trials) with each KLU ordering candidate (KluOrdering::trials), as
/// "klu / camd multipliers last / camd frames and multipliers last".
inline std::string orderingFills(const System& sys) {
  const ConsistentState init = computeConsistentState(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities());
  const DaeSystem dae(sys, Formulation::Ggl);
  VecX y, yp;
  dae.packState(init.q, init.v, init.a, init.lambda, y, yp);
  std::string out;
  for (const KluOrdering& o : KluOrdering::trials(dae, 0.0, y, yp, kOrderingTrialCj)) {
    out += (out.empty() ? "" : "/") + std::to_string(o.factorNonZeros());
  }
  return out;
}

/// Body-frame position of a material point of a flexible body: u0 + N q_f.
inline Vec2 ffrMaterialPoint(const System& sys, const std::string& body, const FfrPoint& p, const VecX& q) {
  const BodyIndex b = sys.findBody(body);
  const int off = sys.coordinateOffset(b);
  const int nf = sys.body(b).numCoordinates() - 3;
  const VecX qf = q.segment(off + 3, nf);
  Vec2 u = p.position;
  u += p.shape * qf;
  return u;
}
/// World position of a body-frame point u of body `body` (frame coordinates x, y, theta).
inline Vec2 worldPoint(const System& sys, const std::string& body, const Vec2& u, const VecX& q) {
  const int off = sys.coordinateOffset(sys.findBody(body));
  const double c = std::cos(q[off + 2]), s = std::sin(q[off + 2]);
  return {q[off] + c * u.x() - s * u.y(), q[off + 1] + s * u.x() + c * u.y()};
}
/// The material point of a beam body at body-frame point `at` (on the undeformed axis).
inline FfrPoint beamPoint(const System& sys, const std::string& body, const Vec2& at) {
  const auto* ffr = dynamic_cast<const FfrBody2d*>(&sys.body(sys.findBody(body)));
  if (!ffr || !ffr->beamModel()) throw std::logic_error(body + " is not a beam body");
  int e = 0;
  double xi = 0;
  if (!ffr->beamModel()->locate(at, e, xi)) throw std::logic_error("no beam point there");
  return ffr->beamModel()->materialPoint(e, xi);
}

// ---------------------------------------------------------------------------------
// Rigid slider-crank: closed form of source document 000 (eqs. 30-32).

inline BenchModel rigidSliderCrank() {
  BenchModel m;
  m.group = "rigid_slider_crank";
  m.model = "rigid";
  m.span = 2 * M_PI;
  m.length = 1.0;  // crank length l1
  m.positionsDoc = "slider x, rod midpoint (x, y); length = crank l1 = 1 m";
  m.build = [span = m.span, k = m.checkpoints](double rtol, double atol) {
    Scene s = loadScene(sourcePath("examples/slider_crank_rigid.json"));
    setRun(s.solver, rtol, atol, span, k);
    return s;
  };
  m.probe = [](const Scene& s, const OutputSample& o) {
    const System& sys = s.system;
    const int ix = sys.coordinateOffset(sys.findBody("slider"));
    const Vec2 mid = worldPoint(sys, "rod", {1.0, 0.0}, o.q);
    Probe p;
    p.positions = {o.q[ix], mid.x(), mid.y()};
    return p;
  };
  m.exact = [](double t) {
    const auto ref = reference::sliderCrank(1.0, 2.0, t);
    // crank pin (cos t, sin t), slider (x, 0): the rod midpoint is halfway
    return std::vector<double>{ref.x, 0.5 * (std::cos(t) + ref.x), 0.5 * std::sin(t)};
  };
  return m;
}

// ---------------------------------------------------------------------------------
// Elastic slider-crank (examples/slider_crank_elastic.json): no closed form.

inline BenchModel elasticSliderCrank(int elements, int modes, double revolutions, const std::string& group) {
  BenchModel m;
  m.group = group;
  m.elements = elements;
  m.modes = modes;
  m.model = modes ? std::to_string(modes) + " modes" : "nodal";
  m.span = revolutions * 2 * M_PI / 150.0;
  m.checkpoints = static_cast<int>(std::lround(8 * revolutions));  // every 1/8 revolution
  m.length = 0.15;  // crank length
  m.positionsDoc = "slider x, rod midpoint world (x, y) incl. deflection; length = crank 0.15 m";
  m.build = [elements, modes, revolutions, k = m.checkpoints, span = m.span](double rtol, double atol) {
    Scene s = testmodels::elasticSliderCrank(elements, 1.0, modes, revolutions, rtol, atol);
    s.solver.outputStep = span / k;
    return s;
  };
  m.probe = [](const Scene& s, const OutputSample& o) {
    const System& sys = s.system;
    const Vec2 u = ffrMaterialPoint(sys, "rod", beamPoint(sys, "rod", {0.15, 0.0}), o.q);
    const Vec2 w = worldPoint(sys, "rod", u, o.q);
    Probe p;
    p.positions = {o.q[sys.coordinateOffset(sys.findBody("slider"))], w.x(), w.y()};
    p.deflection = u.y();
    return p;
  };
  return m;
}

// ---------------------------------------------------------------------------------
// Free-flying, spinning free-free beam: no closed form; energy and momenta conserved.

constexpr double kBeamLength = 0.3, kBeamSpin = 150.0, kBeamEndAmplitude = 1e-3;

inline BenchModel freeBeam(int elements = 8, int modes = 0) {
  BenchModel m;
  m.group = "free_beam";
  m.elements = elements;
  m.modes = modes;
  m.model = modes ? std::to_string(modes) + " modes" : "nodal";
  m.span = 2 * M_PI / kBeamSpin;
  m.length = kBeamLength;
  m.positionsDoc = "world (x, y) of both ends and the midpoint; length = beam 0.3 m";
  m.build = [elements, modes, span = m.span, k = m.checkpoints](double rtol, double atol) {
    const BeamSection steel = rectangularSection(0.008, 0.008, 2e11, 7870);
    FfrBeamOptions o;
    o.reference.type = ReferenceConditions::Type::FreeFree;
    o.modes = modes;
    auto model = std::make_shared<FfrBeamModel>(
        BeamMesh2d::straight(kBeamLength, elements, steel, {-0.5 * kBeamLength, 0.0}), o, "beam");
    // first free-free bending mode (K phi = w^2 M phi), scaled to kBeamEndAmplitude at the ends
    const MatX K = model->invariants().kff, M = model->invariants().mff;
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> es(K, M);
    VecX mode = es.eigenvectors().col(0);
    int e = 0;
    double xi = 0;
    model->locate({0.5 * kBeamLength, 0.0}, e, xi);
    const Vec2 endShape = model->materialPoint(e, xi).shape * mode;
    mode *= kBeamEndAmplitude / std::abs(endShape.y());
    auto body = std::make_unique<FfrBody2d>("beam", model,
                                            FrameState2d{{0.0, 0.0}, 0.3, {1.0, 0.5}, kBeamSpin});
    body->setInitialElasticState(mode, VecX::Zero(mode.size()));
    Scene s;
    s.name = "free_beam";
    s.system.addBody(std::move(body));
    s.system.finalize();
    setRun(s.solver, rtol, atol, span, k);
    return s;
  };
  m.probe = [](const Scene& s, const OutputSample& o) {
    const System& sys = s.system;
    Probe p;
    for (double x : {-0.5 * kBeamLength, 0.0, 0.5 * kBeamLength}) {
      const Vec2 w = worldPoint(sys, "beam", ffrMaterialPoint(sys, "beam", beamPoint(sys, "beam", {x, 0.0}), o.q), o.q);
      p.positions.push_back(w.x());
      p.positions.push_back(w.y());
    }
    p.energy = kineticEnergy(sys, o.q, o.v) + potentialEnergy(sys, o.q);
    const VecX mom = massMatrix(sys, o.q) * o.v;  // generalised momenta
    p.momentum = mom.head<2>();
    p.angularMomentum = mom[2] + o.q[0] * mom[1] - o.q[1] * mom[0];
    return p;
  };
  return m;
}

// ---------------------------------------------------------------------------------
// Physical pendulum released from rest at phi0: closed form by Jacobi's amplitude,
// sin(phi/2) = k sn(K - w0 t, k), k = sin(phi0/2), w0 = sqrt(m g L / I_pivot).

constexpr double kPendMass = 2.0, kPendInertia = 0.05, kPendLength = 0.8, kPendGravity = 9.81;
inline double pendulumPhi0() { return 170.0 * M_PI / 180.0; }

/// Jacobi amplitude am(u, k): the phi with F(phi, k) = u (Newton on the reduced argument).
inline double jacobiAmplitude(double u, double k) {
  const double K = std::comp_ellint_1(k);
  const double n = std::round(u / (2 * K));
  const double r = u - 2 * K * n;  // in [-K, K]
  const double sgn = r < 0 ? -1.0 : 1.0, a = std::abs(r);
  double phi = std::min(a, M_PI / 2);
  for (int it = 0; it < 100; ++it) {
    const double f = std::ellint_1(k, phi) - a;
    const double d = f * std::sqrt(1 - k * k * std::sin(phi) * std::sin(phi));
    phi = std::clamp(phi - d, 0.0, M_PI / 2);
    if (std::abs(d) < 1e-16) break;
  }
  return sgn * phi + n * M_PI;
}

inline double pendulumAngle(double t) {
  const double Ip = kPendInertia + kPendMass * kPendLength * kPendLength;
  const double w0 = std::sqrt(kPendMass * kPendGravity * kPendLength / Ip);
  const double k = std::sin(0.5 * pendulumPhi0());
  const double sn = std::sin(jacobiAmplitude(std::comp_ellint_1(k) - w0 * t, k));
  return 2 * std::asin(std::clamp(k * sn, -1.0, 1.0));
}

inline BenchModel pendulum() {
  BenchModel m;
  m.group = "pendulum";
  m.model = "rigid";
  const double Ip = kPendInertia + kPendMass * kPendLength * kPendLength;
  const double T = reference::pendulumPeriod(kPendMass, Ip, kPendLength, kPendGravity, pendulumPhi0());
  m.span = 2 * T;
  m.checkpoints = 16;  // every 1/8 period
  m.length = kPendLength;
  m.positionsDoc = "centre of mass (x, y); length = pivot to centre of mass 0.8 m";
  m.build = [span = m.span, k = m.checkpoints](double rtol, double atol) {
    nlohmann::json j = {
        {"name", "pendulum"},
        {"gravity", {0.0, -kPendGravity}},
        {"bodies", {{{"name", "bob"}, {"type", "rigid"}, {"mass", kPendMass}, {"inertia", kPendInertia},
                     {"com", {kPendLength, 0.0}}, {"angle", pendulumPhi0() - M_PI / 2}}}},
        {"joints", {{{"name", "pivot"}, {"type", "revolute"}, {"bodies", {"ground", "bob"}},
                     {"points", {{0.0, 0.0}, {0.0, 0.0}}}}}},
        {"solver", {{"rtol", rtol}, {"atol", atol}, {"t_end", span}, {"output_step", span / k}}}};
    Scene s = parseScene(j);
    s.solver.progress = false;
    return s;
  };
  m.probe = [](const Scene& s, const OutputSample& o) {
    const Vec2 c = worldPoint(s.system, "bob", {kPendLength, 0.0}, o.q);
    Probe p;
    p.positions = {c.x(), c.y()};
    p.energy = kineticEnergy(s.system, o.q, o.v) + potentialEnergy(s.system, o.q);
    return p;
  };
  m.exact = [](double t) {
    const double phi = pendulumAngle(t);
    return std::vector<double>{kPendLength * std::sin(phi), -kPendLength * std::cos(phi)};
  };
  return m;
}

/// All models of the work-precision study, in order.
inline std::vector<BenchModel> allModels() {
  std::vector<BenchModel> v;
  v.push_back(rigidSliderCrank());
  for (int modes : {0, 2, 4}) v.push_back(elasticSliderCrank(8, modes, 1.0, "elastic_1rev"));
  for (int modes : {0, 2, 4}) v.push_back(elasticSliderCrank(8, modes, 5.0, "elastic_5rev"));
  v.push_back(freeBeam(8, 0));
  v.push_back(freeBeam(8, 3));
  v.push_back(pendulum());
  return v;
}

/// Unknowns of the DAE: 2 nq + 2 m (GGL), 2 nq + m (index 3 and 1).
inline int daeSize(const System& sys, Formulation f) {
  return 2 * sys.numCoordinates() + (f == Formulation::Ggl ? 2 : 1) * sys.numConstraintEquations();
}

/// One run of a model: outputs at its checkpoints, probes recorded.
struct RunResult {
  SimulationSummary summary;
  double seconds = 0;             ///< wall time of simulate() (initialisation included)
  std::vector<double> times;      ///< output times (t0 and the checkpoints)
  std::vector<Probe> probes;
  int size = 0;                   ///< DAE size
};

/// Runs `scene` once, recording the probes at every output.
inline RunResult runModel(const BenchModel& m, Scene& scene) {
  RunResult r;
  r.size = daeSize(scene.system, scene.solver.formulation);
  const auto t0 = Clock::now();
  r.summary = simulate(scene.system, scene.solver, [&](const OutputSample& o) {
    r.times.push_back(o.t);
    r.probes.push_back(m.probe(scene, o));
  });
  r.seconds = secondsSince(t0);
  return r;
}

/// Max over checkpoints 1..K and position components of |p - p_ref| / length.
inline double positionError(const BenchModel& m, const std::vector<Probe>& run,
                            const std::vector<std::vector<double>>& ref) {
  if (run.size() != ref.size()) return NAN;
  double e = 0;
  for (std::size_t k = 1; k < run.size(); ++k) {
    for (std::size_t i = 0; i < ref[k].size(); ++i) {
      e = std::max(e, std::abs(run[k].positions.at(i) - ref[k][i]) / m.length);
    }
  }
  return e;
}

}  // namespace flexmbd::bench
