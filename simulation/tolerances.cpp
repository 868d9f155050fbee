#include "simulation/tolerances.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "integrators/initial_conditions.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {
namespace {

/// The time over which the default velocity tolerance moves a point by atol: 1 s. The model's own time scale T = L / V0 was measured as the default
/// and not kept: velocity tolerances 1 / T = 31 to 150 times looser on the flexible
/// examples halved their steps but made their elastic coordinates 4 to 30 times less
/// accurate at the scenes' own settings (the elastic rates' tolerance sets that
/// accuracy; docs/formulations.md).
constexpr double kVelocityTimeScale = 1.0;

/// Multipliers: large, so that the algebraic variables (already out of the error test)
/// stay out of the Newton convergence test too.
constexpr double kAtolMultiplier = 1e10;

/// Inverse iteration for the lowest elastic mode: it converges as (omega_1 / omega_2)^2
/// per iteration; 1e-6 relative on omega_1^2 is far finer than a tolerance scale needs,
/// and 50 iterations reach it unless the two lowest modes are within 25 % of each other
/// (then the Rayleigh quotient is still within that of omega_1^2, enough for a scale).
constexpr int kMaxInverseIterations = 50;
constexpr double kInverseIterationTolerance = 1e-6;

/// Largest speed of the initial state: frame velocities, and angular rates times L.
double largestInitialSpeed(const System& sys, const VecX& v0, double L) {
  const std::vector<CoordinateKind> kinds = sys.velocityKinds();
  double speed = 0.0;
  for (int k = 0; k < v0.size(); ++k) {
    if (kinds[k] == CoordinateKind::Position) speed = std::max(speed, std::fabs(v0[k]));
    if (kinds[k] == CoordinateKind::Angle) speed = std::max(speed, std::fabs(v0[k]) * L);
  }
  return speed;
}

/// Squared lowest natural frequency omega_1^2 of K phi = omega^2 M phi (both symmetric
/// positive definite, the bodies validate them) by inverse iteration (GolubVanLoan2013) from a start with
/// a component along every mode in practice; 0 if K cannot be factorised.
double lowestSquaredFrequency(const SpMat& M, const SpMat& K) {
  const Eigen::SimplicialLDLT<SpMat> ldlt(K);
  if (ldlt.info() != Eigen::Success) return 0.0;
  const int n = static_cast<int>(K.rows());
  VecX x(n);
  for (int i = 0; i < n; ++i) x[i] = 1.0 + 0.5 * std::sin(1.0 + i);  // no symmetry of the mesh
  double lambda = 0.0;
  for (int it = 0; it < kMaxInverseIterations; ++it) {
    VecX y = ldlt.solve(M * x);               // y = K^-1 M x (inverse iteration, GolubVanLoan2013)
    const double yMy = y.dot(M * y);
    if (!(yMy > 0.0)) return 0.0;
    y /= std::sqrt(yMy);
    const double next = y.dot(K * y);         // Rayleigh quotient, y^T M y = 1 (GeradinRixen)
    x = y;
    if (std::fabs(next - lambda) <= kInverseIterationTolerance * next) return next;
    lambda = next;
  }
  return lambda;
}

/// Positive and finite, or InputError naming the option.
void requirePositive(double value, const char* key) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    std::ostringstream os;
    os << "solver." << key << ": expected a positive number, got " << value;
    throw InputError(os.str());
  }
}

}  // namespace

ModelScales modelScales(const System& sys, const VecX& v0, double tStart, double tEnd) {
  ModelScales m;
  m.length = sys.characteristicLength();
  const double span = tEnd - tStart;
  const double fall = std::sqrt(sys.gravity().norm() * m.length);  // speed after falling through L
  m.speed = std::max({largestInitialSpeed(sys, v0, m.length), fall, m.length / span});
  m.timeScale = m.length / m.speed;  // T = L / V0
  const double acceleration = m.length / (m.timeScale * m.timeScale);  // a = L / T^2
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex{b});
    const Body::ElasticMatrices em = body.elasticMatrices();
    if (!em.mass || !em.stiffness || em.mass->rows() == 0) continue;
    const double omega2 = lowestSquaredFrequency(*em.mass, *em.stiffness);
    if (!(omega2 > 0.0)) continue;
    const double deflection = acceleration / omega2;  // quasi-static: omega_1^2 eta = a
    if (deflection > m.elasticSize) {
      m.elasticSize = deflection;
      m.elasticBody = body.name();
      m.lowestFrequency = std::sqrt(omega2);
    }
  }
  return m;
}

ModelScales modelScales(const System& sys, const SolverSettings& settings) {
  const ConsistentState init =
      computeConsistentState(sys, settings.tStart, sys.initialCoordinates(), sys.initialVelocities());
  return modelScales(sys, init.v, settings.tStart, settings.tEnd);
}

ClassTolerances classTolerances(const SolverSettings& s, const ModelScales& m) {
  ClassTolerances t;
  t.rtol = s.rtol;
  t.position = s.atol;
  // angles: atol in rad. atol / L (a rotation moving a point at L by
  // atol) was measured: it changed the examples' results and cost (parallelogram_undriven
  // twice the steps; an index-1 test 5 times less accurate where L < 1 m), so it is
  // reported (ModelScales::length) but not the default.
  t.angle = s.atolAngle.value_or(s.atol);
  t.velocity = s.atolVelocity.value_or(s.atol / kVelocityTimeScale);  // moves a point by atol within 1 s
  // a nodal or modal coordinate moves material points by its own value: a length
  // (atol s_e / L would shrink like 1 / E on a stiffening rod: ModelScales::elasticSize)
  t.elastic = s.atolElastic.value_or(s.atol);
  const double rateRatio = t.velocity / t.position;
  t.angularVelocity = t.angle * rateRatio;
  t.elasticVelocity = t.elastic * rateRatio;
  // round-off floors (kRoundOff*)
  const double speedFloor = kRoundOffFractionOfSpeed * m.speed;
  t.angle = std::max(t.angle, kRoundOffAngle);
  t.elastic = std::max(t.elastic, kRoundOffFractionOfSize * (m.elasticSize > 0.0 ? m.elasticSize : m.length));
  t.velocity = std::max(t.velocity, speedFloor);
  t.angularVelocity = std::max(t.angularVelocity, speedFloor / m.length);
  t.elasticVelocity = std::max(t.elasticVelocity, speedFloor);
  return t;
}

VecX absoluteTolerances(const DaeSystem& dae, const ClassTolerances& tol) {
  const DaeLayout& L = dae.layout();
  const System& sys = dae.system();
  const auto ofKind = [&](CoordinateKind kind) {
    return kind == CoordinateKind::Position ? tol.position : kind == CoordinateKind::Angle ? tol.angle : tol.elastic;
  };
  const auto rateOfKind = [&](CoordinateKind kind) {
    return kind == CoordinateKind::Position ? tol.velocity
           : kind == CoordinateKind::Angle  ? tol.angularVelocity
                                            : tol.elasticVelocity;
  };
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds(), vkinds = sys.velocityKinds();
  VecX atol = VecX::Constant(L.size, kAtolMultiplier);
  for (int k = 0; k < L.nq; ++k) atol[L.q + k] = ofKind(kinds[k]);
  for (int k = 0; k < L.nv; ++k) atol[L.v + k] = rateOfKind(vkinds[k]);
  return atol;
}

void overrideTolerances(SolverSettings& s, std::optional<double> rtol, std::optional<double> atol) {
  if (rtol) requirePositive(*rtol, "rtol");
  if (atol) requirePositive(*atol, "atol");
  // the factor of every absolute tolerance: atol's own, or rtol's when atol is not given
  const double factor = atol ? *atol / s.atol : rtol ? *rtol / s.rtol : 1.0;
  if (rtol) s.rtol = *rtol;
  s.atol = atol ? *atol : s.atol * factor;
  for (std::optional<double>* cls : {&s.atolAngle, &s.atolElastic, &s.atolVelocity}) {
    if (*cls) **cls *= factor;
  }
}

}  // namespace flexmbd
