// Diagnosis: why a scene takes the steps it takes. Runs a scene with
// SUNDIALS IDA one step at a time (dense LU, the engine's residual and Jacobian) and
// records per step the size and order, and which unknown dominates the weighted local
// error estimate (IDAGetEstLocalErrors x IDAGetErrWeights), grouped by coordinate class
// (frame, elastic; positions, velocities); and the modal content of every flexible body's
// elastic coordinates (amplitude and energy per mode of K_ff phi = omega^2 M_ff phi).
//
//   diag_steps SCENE.json [--t-end T] [--rtol R] [--atol A] [--every N]
#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include "core/dae_system.hpp"
#include "integrators/initial_conditions.hpp"
#include "analysis/quasi_static_start.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;

namespace {

struct User {
  const DaeSystem* dae;
  std::unique_ptr<DaeScratch> scratch;
};

int res(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* u) {
  auto* d = static_cast<User*>(u);
  d->dae->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r), *d->scratch);
  return 0;
}

int jac(realtype t, realtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J, void* u, N_Vector, N_Vector,
        N_Vector) {
  auto* d = static_cast<User*>(u);
  SUNMatZero(J);
  JacobianSink sink = JacobianSink::dense(SUNDenseMatrix_Data(J), d->dae->pattern().size());
  d->dae->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), cj, sink, *d->scratch);
  return 0;
}

struct ModeRecord {
  std::string name;
  int offset = 0, nf = 0;  // elastic coordinates q[offset .. offset + nf)
  VecX omega;
  MatX phiTM;  // Phi^T M: modal coordinates eta = Phi^T M q_f
  VecX maxAmp, maxEnergy, maxDyn;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: diag_steps SCENE.json [--t-end T] [--rtol R] [--atol A] [--every N]\n");
    return 2;
  }
  Scene scene = loadScene(argv[1]);
  long every = 1000;
  double qsCutoff = 0.0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    const double v = std::atof(argv[i + 1]);
    if (k == "--t-end") scene.solver.tEnd = v;
    if (k == "--rtol") scene.solver.rtol = v;
    if (k == "--atol") scene.solver.atol = v;
    if (k == "--every") every = static_cast<long>(v);
    if (k == "--qs") qsCutoff = v;
    if (k == "--integrator-order") scene.solver.maxOrder = static_cast<int>(v);
  }
  const System& sys = scene.system;
  const SolverSettings& s = scene.solver;
  ConsistentState init = computeConsistentState(sys, s.tStart, sys.initialCoordinates(), sys.initialVelocities());
  if (qsCutoff > 0) {
    const QuasiStaticStart r = quasiStaticElasticStart(sys, s.tStart, init, elasticModes(sys), qsCutoff);
    std::printf("# quasi-static start: %d modes, %d iterations, residual %g\n", r.modes, r.iterations, r.residual);
    init = r.state;
  }
  const DaeSystem dae(sys, s.formulation);
  const DaeLayout& L = dae.layout();
  VecX y0, yp0;
  dae.packState(init.q, init.v, init.a, init.lambda, y0, yp0);
  const int n = L.size;

  // class of each unknown: body name + kind
  std::vector<std::string> cls(n, "multiplier");
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds();
  const std::vector<std::string> names = sys.coordinateNames();
  for (int k = 0; k < L.nq; ++k) {
    const char* kind = kinds[k] == CoordinateKind::Elastic ? "elastic" : "frame";
    cls[L.q + k] = std::string(kind) + " q";
    cls[L.v + k] = std::string(kind) + " v";
  }
  std::vector<ModeRecord> bodies;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex{b});
    const Body::ElasticMatrices em = body.elasticMatrices();
    if (!em.mass) continue;
    ModeRecord m;
    m.name = body.name();
    m.nf = static_cast<int>(em.mass->rows());
    m.offset = sys.coordinateOffset(BodyIndex{b}) + sys.numCoordinates(BodyIndex{b}) - m.nf;
    const MatX M(*em.mass), K(*em.stiffness);
    Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(K, M);
    m.omega = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    m.phiTM = eig.eigenvectors().transpose() * M;
    m.maxAmp = VecX::Zero(m.nf);
    m.maxEnergy = VecX::Zero(m.nf);
    m.maxDyn = VecX::Zero(m.nf);
    bodies.push_back(m);
  }

  SUNContext ctx;
  SUNContext_Create(nullptr, &ctx);
  N_Vector yy = N_VNew_Serial(n, ctx), yp = N_VNew_Serial(n, ctx), at = N_VNew_Serial(n, ctx),
           id = N_VNew_Serial(n, ctx), ele = N_VNew_Serial(n, ctx), ew = N_VNew_Serial(n, ctx);
  Eigen::Map<VecX>(N_VGetArrayPointer(yy), n) = y0;
  Eigen::Map<VecX>(N_VGetArrayPointer(yp), n) = yp0;
  Eigen::Map<VecX>(N_VGetArrayPointer(at), n) = absoluteTolerances(dae, s);
  Eigen::Map<VecX>(N_VGetArrayPointer(id), n) = dae.differentialIds();
  User user{&dae, dae.makeScratch()};
  void* mem = IDACreate(ctx);
  IDAInit(mem, res, s.tStart, yy, yp);
  IDASVtolerances(mem, s.rtol, at);
  IDASetUserData(mem, &user);
  IDASetId(mem, id);
  IDASetSuppressAlg(mem, SUNTRUE);
  IDASetMaxNumSteps(mem, 100000000);
  IDASetMaxOrd(mem, s.maxOrder);
  IDASetStopTime(mem, s.tEnd);
  SUNMatrix A = SUNDenseMatrix(n, n, ctx);
  SUNLinearSolver LS = SUNLinSol_Dense(yy, A, ctx);
  IDASetLinearSolver(mem, LS, A);
  IDASetJacFn(mem, jac);

  std::map<std::string, long> dominant;
  std::map<int, long> orders;
  std::map<int, long> domIndex;
  long steps = 0;
  double t = s.tStart;
  std::printf("# t h order dominant_class dominant_coordinate weighted_error\n");
  while (t < s.tEnd) {
    if (IDASolve(mem, s.tEnd, &t, yy, yp, IDA_ONE_STEP) < 0) {
      std::printf("failed at %g\n", t);
      break;
    }
    ++steps;
    int order = 0;
    double h = 0;
    IDAGetLastOrder(mem, &order);
    IDAGetLastStep(mem, &h);
    IDAGetEstLocalErrors(mem, ele);
    IDAGetErrWeights(mem, ew);
    const double* e = N_VGetArrayPointer(ele);
    const double* w = N_VGetArrayPointer(ew);
    const double* idv = N_VGetArrayPointer(id);
    int imax = 0;
    double emax = -1;
    for (int i = 0; i < n; ++i) {
      if (idv[i] == 0.0) continue;
      const double x = std::fabs(e[i] * w[i]);
      if (x > emax) emax = x, imax = i;
    }
    dominant[cls[imax]]++;
    domIndex[imax]++;
    orders[order]++;
    const double* yv = N_VGetArrayPointer(yy);
    for (ModeRecord& m : bodies) {
      const VecX eta = m.phiTM * Eigen::Map<const VecX>(yv + L.q + m.offset, m.nf);
      const VecX etad = m.phiTM * Eigen::Map<const VecX>(yv + L.v + m.offset, m.nf);
      const VecX etadd = m.phiTM * Eigen::Map<const VecX>(N_VGetArrayPointer(yp) + L.v + m.offset, m.nf);
      for (int i = 0; i < m.nf; ++i) {
        m.maxAmp[i] = std::max(m.maxAmp[i], std::fabs(eta[i]));
        if (t > 0.1 * s.tEnd) m.maxDyn[i] = std::max(m.maxDyn[i], std::fabs(etadd[i]) / (m.omega[i] * m.omega[i]));
        m.maxEnergy[i] = std::max(m.maxEnergy[i], 0.5 * (etad[i] * etad[i] + m.omega[i] * m.omega[i] * eta[i] * eta[i]));
      }
    }
    if (steps % every == 0) {
      const int k = imax >= L.v && imax < L.v + L.nv ? imax - L.v : imax - L.q;
      std::printf("%.6e %.3e %d %s %s %.3f\n", t, h, order, cls[imax].c_str(),
                  k >= 0 && k < L.nq ? names[k].c_str() : "?", emax);
    }
  }
  long nre = 0, netf = 0;
  IDAGetNumResEvals(mem, &nre);
  IDAGetNumErrTestFails(mem, &netf);
  std::printf("\nsteps %ld, residuals %ld, error-test failures %ld\norders:", steps, nre, netf);
  for (auto& [o, c] : orders) std::printf(" %d:%ld", o, c);
  std::printf("\ndominant class of the weighted local error (steps):\n");
  for (auto& [c, k] : dominant) std::printf("  %-12s %ld\n", c.c_str(), k);
  std::printf("dominant unknowns (top):\n");
  std::vector<std::pair<long, int>> top;
  for (auto& [i, c] : domIndex) top.push_back({c, i});
  std::sort(top.rbegin(), top.rend());
  for (size_t j = 0; j < top.size() && j < 8; ++j) {
    const int i = top[j].second;
    const bool vel = i >= L.v && i < L.v + L.nv;
    const int k = vel ? i - L.v : i - L.q;
    std::printf("  %s%s %ld\n", k >= 0 && k < L.nq ? names[k].c_str() : "mult", vel ? "_dot" : "", top[j].first);
  }
  for (const ModeRecord& m : bodies) {
    std::printf("body %s: mode omega(rad/s) max|eta| max energy (per unit modal mass) max|eta''/omega^2| (t > t_end/10)\n", m.name.c_str());
    for (int i = 0; i < m.nf; ++i) {
      std::printf("  %2d %12.1f %12.4e %12.4e %12.4e\n", i + 1, m.omega[i], m.maxAmp[i], m.maxEnergy[i], m.maxDyn[i]);
    }
  }
  IDAFree(&mem);
  return 0;
}
