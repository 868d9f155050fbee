#include "analysis/quasi_static_start.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/system_evaluation.hpp"

namespace flexmbd {
namespace {

/// Newton iterations on the fast modes' accelerations, and fixed-point iterations on their
/// jerks: both converge in 2 to 4 (the map is affine up to the frame's geometric
/// nonlinearity; measured on the demo's rod).
constexpr int kMaxIterations = 20;
/// Converged when the largest change of an elastic coordinate (or rate) is below this
/// fraction of the largest one: round-off of the projections is ~1e-14 of it.
constexpr double kRelativeChange = 1e-10;
/// Constraint residual accepted by projectKeepingElastic, relative to the largest coordinate.
constexpr double kProjectionTolerance = 1e-14;
/// Time step of the central differences for the modal jerk, as a fraction of the period
/// scale 1/cutoff: far below every period of the modes concerned, far above round-off.
constexpr double kJerkStepFraction = 1e-4;
/// Perturbation of a fast mode for the difference quotients of its acceleration: this
/// fraction of the static deflection scale (largest |eta_k''| / omega_k^2), or of the
/// largest elastic coordinate if that is larger (the map is affine: any small step works).
constexpr double kPerturbationFraction = 1e-3;

/// A fast mode: body b, mode k.
struct FastMode {
  int body = 0, mode = 0;
};

std::vector<FastMode> fastModes(const std::vector<BodyModes>& modes, double cutoff) {
  std::vector<FastMode> f;
  for (int b = 0; b < static_cast<int>(modes.size()); ++b) {
    for (int k = 0; k < modes[b].size(); ++k) {
      if (modes[b].omega[k] > cutoff) f.push_back({b, k});
    }
  }
  return f;
}

/// The modal components eta_k = phi_k^T M_ff x_f of the fast modes, from a velocity-space
/// vector x (velocities, accelerations, jerks).
VecX fastComponents(const std::vector<BodyModes>& modes, const std::vector<FastMode>& fast, const VecX& x) {
  VecX c(static_cast<int>(fast.size()));
  for (size_t i = 0; i < fast.size(); ++i) {
    const BodyModes& m = modes[fast[i].body];
    c[i] = m.projector.row(fast[i].mode).dot(x.segment(m.velocityOffset, m.size()));
  }
  return c;
}

/// x_f += sum_i d_i phi_i over the fast modes; `coordinates`: x is q (else v).
void addModes(const std::vector<BodyModes>& modes, const std::vector<FastMode>& fast, const VecX& d, bool coordinates,
              VecX& x) {
  for (size_t i = 0; i < fast.size(); ++i) {
    const BodyModes& m = modes[fast[i].body];
    x.segment(coordinates ? m.coordinateOffset : m.velocityOffset, m.size()) += d[i] * m.shapes.col(fast[i].mode);
  }
}

double largestElastic(const std::vector<BodyModes>& modes, const VecX& x, bool coordinates) {
  double s = 0.0;
  for (const BodyModes& m : modes) {
    s = std::max(s, x.segment(coordinates ? m.coordinateOffset : m.velocityOffset, m.size()).lpNorm<Eigen::Infinity>());
  }
  return s;
}

/// The largest change of an elastic coordinate (or rate) that the modal step d makes.
double elasticChange(const std::vector<BodyModes>& modes, const std::vector<FastMode>& fast, const VecX& d,
                     bool coordinates, const VecX& like) {
  VecX x = VecX::Zero(like.size());
  addModes(modes, fast, d, coordinates, x);
  return x.lpNorm<Eigen::Infinity>();
}

/// q moved back onto g(q, t) = 0 by minimum-norm Newton corrections of every coordinate
/// except the elastic ones of `modes` (set by the caller): the projection of
/// computeConsistentState would spread its correction into them and undo part of the step.
/// @throws ModelError if it does not converge.
VecX projectKeepingElastic(const System& sys, double t, VecX q, const std::vector<BodyModes>& modes) {
  const double scale = std::max(1.0, q.lpNorm<Eigen::Infinity>());
  for (int it = 0; it < kMaxIterations; ++it) {
    VecX g;
    MatX G;
    evaluateConstraints(sys, q, t, &g, &G);
    if (g.size() == 0 || g.lpNorm<Eigen::Infinity>() <= kProjectionTolerance * scale) return q;
    for (const BodyModes& m : modes) G.middleCols(m.velocityOffset, m.size()).setZero();
    q = sys.applyIncrement(q, -G.completeOrthogonalDecomposition().solve(g));
  }
  throw ModelError("quasi-static elastic start: the joints cannot be closed by the frame coordinates alone");
}

/// The consistent state with the fast modes' coordinates moved by d (elastic coordinates
/// kept, the others projected on the constraints, velocities projected, accelerations).
ConsistentState movedState(const System& sys, double t0, const ConsistentState& s, const std::vector<BodyModes>& modes,
                           const std::vector<FastMode>& fast, const VecX& d) {
  VecX q = s.q;
  addModes(modes, fast, d, true, q);
  return computeConsistentState(sys, t0, projectKeepingElastic(sys, t0, q, modes), s.v, {false, s.released});
}

bool converged(double change, double size) {
  return change <= kRelativeChange * size || change <= std::numeric_limits<double>::min();
}

}  // namespace

QuasiStaticStart quasiStaticElasticStart(const System& sys, double t0, const ConsistentState& start,
                                         const std::vector<BodyModes>& modes, double cutoff) {
  QuasiStaticStart out;
  out.state = start;
  const std::vector<FastMode> fast = fastModes(modes, cutoff);
  out.modes = static_cast<int>(fast.size());
  if (fast.empty()) return out;
  const int n = out.modes;
  VecX omega2(n);
  for (int i = 0; i < n; ++i) omega2[i] = std::pow(modes[fast[i].body].omega[fast[i].mode], 2);
  ConsistentState& s = out.state;
  // positions: Newton on the fast modes' accelerations r(d) = eta_H''(d) = 0, Jacobian by
  // forward differences (affine map: the stiffness -omega^2 plus the coupling through the joints)
  VecX r = fastComponents(modes, fast, s.a);
  const double eps =
      kPerturbationFraction * std::max(r.cwiseQuotient(omega2).lpNorm<Eigen::Infinity>(), largestElastic(modes, s.q, true));
  if (eps > 0.0) {
    MatX J(n, n);
    for (int j = 0; j < n; ++j) {
      VecX d = VecX::Zero(n);
      d[j] = eps;
      J.col(j) = (fastComponents(modes, fast, movedState(sys, t0, s, modes, fast, d).a) - r) / eps;
    }
    const Eigen::PartialPivLU<MatX> lu(J);
    for (int it = 0; it < kMaxIterations; ++it, ++out.iterations) {
      const VecX d = -lu.solve(r);
      if (!d.allFinite()) throw ModelError("quasi-static elastic start: the fast modes' load-deflection map is singular");
      s = movedState(sys, t0, s, modes, fast, d);
      r = fastComponents(modes, fast, s.a);
      if (converged(elasticChange(modes, fast, d, true, s.q), largestElastic(modes, s.q, true))) break;
    }
  }
  // rates: the fast modes' jerks to zero, eta_k' += eta_k''' / omega_k^2, the jerk from the
  // accelerations at t0 -+ dt along the motion
  const double dt = kJerkStepFraction / cutoff;
  for (int it = 0; it < kMaxIterations; ++it, ++out.iterations) {
    VecX ap, am, lp, lm;
    computeAccelerations(sys, t0 + dt, sys.applyIncrement(s.q, dt * s.v), s.v + dt * s.a, ap, lp, s.released);
    computeAccelerations(sys, t0 - dt, sys.applyIncrement(s.q, -dt * s.v), s.v - dt * s.a, am, lm, s.released);
    const VecX jerk = (ap - am) / (2.0 * dt);  // central difference, error O(dt^2)
    const VecX d = fastComponents(modes, fast, jerk).cwiseQuotient(omega2);
    VecX v = s.v;
    addModes(modes, fast, d, false, v);
    s = computeConsistentState(sys, t0, s.q, v, {false, s.released});
    if (converged(elasticChange(modes, fast, d, false, s.v), largestElastic(modes, s.v, false))) break;
  }
  out.residual = fastComponents(modes, fast, s.a).cwiseQuotient(omega2).lpNorm<Eigen::Infinity>();
  return out;
}

}  // namespace flexmbd
