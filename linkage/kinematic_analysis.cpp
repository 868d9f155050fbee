#include "linkage/kinematic_analysis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <utility>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/errors.hpp"
#include "core/stop_request.hpp"
#include "core/number_text.hpp"

namespace flexmbd {
namespace {

/// Significant digits of the numbers in messages (fmt, core/number_text.hpp).
constexpr int kNumberDigits = 10;

std::string joinQuoted(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "'" : ", '") + s + "'";
  return out;
}

double maxAbs(const VecX& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

/// Column scaling to unit max norm, so that the condition number does not depend on
/// the units of lengths against angles.
MatX scaledColumns(const MatX& A) {
  MatX S = A;
  for (int j = 0; j < S.cols(); ++j) {
    const double m = S.col(j).cwiseAbs().maxCoeff();
    if (m > 0.0) S.col(j) /= m;
  }
  return S;
}

}  // namespace

void KinematicSettings::validate() const {
  auto finite = [](double x, const char* key) {
    if (!std::isfinite(x)) {
      throw InputError(std::string("kinematics: ") + key + " must be a finite number, got " + fmt(x, kNumberDigits));
    }
  };
  finite(start, "start");
  finite(end, "end");
  finite(speed, "speed");
  finite(acceleration, "acceleration");
  finite(tolerance, "tolerance");
  if (end == start) throw InputError("kinematics: end must differ from start, both are " + fmt(start, kNumberDigits));
  if (steps < 1) throw InputError("kinematics: steps must be >= 1, got " + std::to_string(steps));
  if (!(tolerance > 0.0)) throw InputError("kinematics: tolerance must be > 0, got " + fmt(tolerance, kNumberDigits));
  if (maxIterations < 1) throw InputError("kinematics: max_iterations must be >= 1, got " + std::to_string(maxIterations));
  if (!(singularTolerance > 0.0 && singularTolerance < 1.0)) {
    throw InputError("kinematics: singular_tolerance must be in (0, 1), got " + fmt(singularTolerance, kNumberDigits));
  }
  if (!(locateTolerance > 0.0) || !std::isfinite(locateTolerance)) {
    throw InputError("kinematics: locate_tolerance must be > 0, got " + fmt(locateTolerance, kNumberDigits));
  }
}

KinematicAnalysis::KinematicAnalysis(const Linkage2d& linkage, const KinematicSettings& settings)
    : linkage_(linkage), settings_(settings) {
  settings_.validate();
  if (!linkage_.isFinalized()) throw InputError("kinematics: the linkage must be finalized first");
  // Assembly at alpha = start: Newton from the given node positions (end angles = chord
  // angles), the inputs at their initial values.
  x0_ = linkage_.initialCoordinates();
  const Correction c = correct(settings_.start, x0_);
  assemblyIterations_ = c.iterations;
  if (!c.converged) {
    const VecX eps = linkage_.deformations(x0_);
    int worst = 0;
    eps.cwiseAbs().maxCoeff(&worst);
    static const char* const kParameter[3] = {"elongation", "rotation at its first node", "rotation at its second node"};
    throw ModelError("the linkage cannot be assembled at alpha = " + fmt(settings_.start, kNumberDigits) +
                     ": residual " + fmt(c.residual, 3) + " after " + std::to_string(c.iterations) +
                     " iterations; largest: link '" + linkage_.link(LinkIndex(worst / 3)).name + "' (" +
                     kParameter[worst % 3] + ")");
  }
  const TransferFunctions tf = transferFunctions(x0_);
  if (!(tf.rcond >= settings_.singularTolerance)) {
    SingularPosition s;
    describeSingularMode(x0_, s);
    throw ModelError("the linkage is singular at the start, alpha = " + fmt(settings_.start, kNumberDigits) +
                     " (D L1 reciprocal condition " + fmt(tf.rcond, 3) + "; nodes " + joinQuoted(s.nodes) +
                     ", links " + joinQuoted(s.links) + "): a lock, dead or change point, or redundant links");
  }
}

VecX KinematicAnalysis::inputValues(double alpha) const {
  const std::vector<int>& in = linkage_.inputCoordinates();
  const VecX rates = linkage_.inputRates();
  const VecX xStart = linkage_.initialCoordinates();
  VecX v(in.size());
  for (std::size_t k = 0; k < in.size(); ++k) v[k] = xStart[in[k]] + rates[k] * (alpha - settings_.start);
  return v;
}

MatX KinematicAnalysis::unknownJacobian(const VecX& X) const {
  const MatX D = linkage_.jacobian(X);
  const std::vector<int>& u = linkage_.unknownCoordinates();
  MatX A(D.rows(), static_cast<int>(u.size()));
  for (std::size_t j = 0; j < u.size(); ++j) A.col(j) = D.col(u[j]);
  return A;
}

KinematicAnalysis::Correction KinematicAnalysis::correct(double alpha, VecX& X, const MatX* frozen) const {
  const std::vector<int>& u = linkage_.unknownCoordinates();
  const std::vector<int>& in = linkage_.inputCoordinates();
  const VecX values = inputValues(alpha);
  for (std::size_t k = 0; k < in.size(); ++k) X[in[k]] = values[k];

  Correction c;
  Eigen::PartialPivLU<MatX> frozenLu;
  if (frozen) frozenLu.compute(*frozen);
  VecX zeta = linkage_.deformations(X);  // residual of the exact deformation parameters
  c.residual = maxAbs(zeta);
  while (c.residual > settings_.tolerance && c.iterations < settings_.maxIterations) {
    VecX du;  // u* = -(D L1)^-1 zeta, Doc000, eq. 27
    if (frozen) {
      du = -frozenLu.solve(zeta);
    } else {
      du = -Eigen::PartialPivLU<MatX>(unknownJacobian(X)).solve(zeta);
    }
    if (!du.allFinite()) break;
    for (std::size_t j = 0; j < u.size(); ++j) X[u[j]] += du[j];
    ++c.iterations;
    zeta = linkage_.deformations(X);
    c.residual = maxAbs(zeta);
    if (!std::isfinite(c.residual)) break;
  }
  c.converged = c.residual <= settings_.tolerance;
  return c;
}

KinematicAnalysis::TransferFunctions KinematicAnalysis::transferFunctions(const VecX& X) const {
  const std::vector<int>& u = linkage_.unknownCoordinates();
  const std::vector<int>& in = linkage_.inputCoordinates();
  const MatX D = linkage_.jacobian(X);
  MatX A(D.rows(), static_cast<int>(u.size())), B(D.rows(), static_cast<int>(in.size()));
  for (std::size_t j = 0; j < u.size(); ++j) A.col(j) = D.col(u[j]);
  for (std::size_t j = 0; j < in.size(); ++j) B.col(j) = D.col(in[j]);

  TransferFunctions tf;
  const Eigen::PartialPivLU<MatX> scaledLu(scaledColumns(A));
  tf.rcond = scaledLu.rcond();
  if (!std::isfinite(tf.rcond)) tf.rcond = 0.0;
  const double det = scaledLu.determinant();  // column scaling is positive: same sign
  tf.determinantSign = det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);

  const Eigen::PartialPivLU<MatX> lu(A);
  const VecX rates = linkage_.inputRates();
  tf.first = VecX::Zero(X.size());
  const VecX x1 = -lu.solve(B * rates);  // Doc000, eq. 22
  for (std::size_t j = 0; j < u.size(); ++j) tf.first[u[j]] = x1[j];
  for (std::size_t j = 0; j < in.size(); ++j) tf.first[in[j]] = rates[j];

  // D X' = 0 along the motion; differentiating once more, D X'' + (dD/dalpha) X' = 0
  // with X''_2 = 0: x''1 = -(D L1)^-1 (dD/dalpha) X' (Doc000, eq. 23).
  tf.second = VecX::Zero(X.size());
  const VecX x2 = -lu.solve(linkage_.secondDerivative(X, tf.first));
  for (std::size_t j = 0; j < u.size(); ++j) tf.second[u[j]] = x2[j];
  return tf;
}

KinematicState KinematicAnalysis::makeState(int step, double alpha, const VecX& X, const Correction& c) const {
  KinematicState s;
  s.step = step;
  s.alpha = alpha;
  s.x = X;
  const TransferFunctions tf = transferFunctions(X);
  s.xp = tf.first;
  s.xpp = tf.second;
  s.rcond = tf.rcond;
  const double w = settings_.speed, wd = settings_.acceleration;
  s.v = s.xp * w;                          // Doc000, eq. 24
  s.a = s.xpp * (w * w) + s.xp * wd;       // Doc000, eq. 25
  s.iterations = c.iterations;
  s.residual = c.residual;
  return s;
}

KinematicState KinematicAnalysis::solve(double alpha, const VecX& guess) const {
  VecX X = guess;
  const Correction c = correct(alpha, X);
  if (!c.converged) {
    throw ModelError("kinematics: no position found at alpha = " + fmt(alpha, kNumberDigits) + " (residual " +
                     fmt(c.residual, 3) + " after " + std::to_string(c.iterations) + " iterations)");
  }
  return makeState(0, alpha, X, c);
}

void KinematicAnalysis::describeSingularMode(const VecX& X, SingularPosition& s) const {
  // The right singular vector of the smallest singular value of the scaled D L1 is the
  // motion the linkage allows with its inputs held: the coordinates in it name the
  // nodes and links involved.
  const MatX A = unknownJacobian(X);
  const MatX S = scaledColumns(A);
  Eigen::JacobiSVD<MatX> svd(S, Eigen::ComputeFullV);
  const VecX mode = svd.matrixV().col(S.cols() - 1);
  const double peak = maxAbs(mode);
  std::vector<char> moves(X.size(), 0);
  const std::vector<int>& u = linkage_.unknownCoordinates();
  for (std::size_t j = 0; j < u.size(); ++j) moves[u[j]] = std::abs(mode[j]) > 1e-3 * peak;
  std::set<int> nodeSet;
  s.links.clear();
  for (int k = 0; k < linkage_.numLinks(); ++k) {
    const Linkage2d::Link& l = linkage_.link(LinkIndex(k));
    if (moves[l.offset] || moves[l.offset + 1]) {
      s.links.push_back(l.name);
      nodeSet.insert(l.nodes[0].value);
      nodeSet.insert(l.nodes[1].value);
    }
  }
  for (int i = 0; i < linkage_.numNodes(); ++i) {
    const Linkage2d::Node& n = linkage_.node(NodeIndex(i));
    const int count = n.kind == Linkage2d::NodeKind::Free ? 2 : (n.kind == Linkage2d::NodeKind::Slider ? 1 : 0);
    for (int c = 0; c < count; ++c) {
      if (moves[n.offset + c]) nodeSet.insert(i);
    }
  }
  s.nodes.clear();
  for (int i : nodeSet) s.nodes.push_back(linkage_.node(NodeIndex(i)).name);
}

SingularPosition KinematicAnalysis::locate(const KinematicState& regular, double alphaBeyond,
                                           bool lockSuspected) const {
  // Bisection between the last regular position and the first alpha where the corrector
  // failed (lock: no position exists) or det(D L1) changed sign (a singular position
  // was crossed). Each trial starts from the nearest regular position.
  const int refSign = transferFunctions(regular.x).determinantSign;
  double lo = regular.alpha, hi = alphaBeyond;
  VecX xLo = regular.x, xpLo = regular.xp, xppLo = regular.xpp;
  bool sawSolutionBeyond = !lockSuspected;
  for (int it = 0; it < 200 && std::abs(hi - lo) > settings_.locateTolerance; ++it) {
    const double mid = 0.5 * (lo + hi), h = mid - lo;
    VecX X = xLo + h * xpLo + 0.5 * h * h * xppLo;
    Correction c = correct(mid, X);
    if (!c.converged) {
      X = xLo;
      c = correct(mid, X);
    }
    TransferFunctions tf;
    if (c.converged) tf = transferFunctions(X);
    if (c.converged && tf.determinantSign == refSign) {
      lo = mid;
      xLo = X;
      xpLo = tf.first;
      xppLo = tf.second;
    } else {
      if (c.converged) sawSolutionBeyond = true;
      hi = mid;
    }
  }
  SingularPosition s;
  s.alpha = 0.5 * (lo + hi);
  s.alphaRegular = lo;
  s.alphaBeyond = hi;
  s.kind = sawSolutionBeyond ? "change point" : "lock";
  describeSingularMode(xLo, s);
  return s;
}

namespace {

/// Largest magnitude a result may have: the bound of scene numbers (kMaxInputMagnitude,
/// scene/json_reader.hpp). Inputs within it can still give results beyond it (an input
/// acceleration of 1e100 rad/s^2 on a 30 cm crank: 3e101 m/s^2).
constexpr double kMaxResultMagnitude = 1e100;

/// The first quantity of a state that is non-finite or beyond kMaxResultMagnitude, with
/// what is wrong ("" if none): a run never reports a position, transfer function,
/// velocity or acceleration that is inf, NaN or absurdly large.
std::string firstOutOfRange(const KinematicState& s) {
  const std::pair<Eigen::ArrayXd, const char*> parts[] = {
      {s.x.array(), "positions"},
      {s.xp.array(), "transfer functions"},
      {s.xpp.array(), "transfer functions"},
      {s.v.array(), "velocities (X' times the input speed)"},
      {s.a.array(), "accelerations (X'' times speed^2 plus X' times the input acceleration)"},
      {Eigen::ArrayXd::Constant(1, s.residual), "residual"}};
  for (const auto& [values, what] : parts) {  // the non-finite first: the more severe
    if (!values.allFinite()) return std::string("non-finite ") + what;
  }
  for (const auto& [values, what] : parts) {
    if (!(values.abs() <= kMaxResultMagnitude).all()) return std::string(what) + " beyond 1e100";
  }
  return "";
}

void stopAtOutOfRange(KinematicSummary& summary, const KinematicState& s, const std::string& what,
                      const KinematicState* prev) {
  summary.ok = false;
  summary.message = what + " at step " + std::to_string(s.step) + ", alpha = " + fmt(s.alpha, kNumberDigits) +
                    " (overflow: are the input speed and acceleration within range?); " +
                    (prev ? "results kept up to alpha = " + fmt(prev->alpha, kNumberDigits) + " (step " +
                                std::to_string(prev->step) + ")"
                          : std::string("no results were written"));
}

}  // namespace

KinematicSummary KinematicAnalysis::run(const std::function<void(const KinematicState&)>& onStep) const {
  const auto t0 = std::chrono::steady_clock::now();
  KinematicSummary summary;
  summary.assemblyIterations = assemblyIterations_;
  const double h = (settings_.end - settings_.start) / settings_.steps;

  Correction c0;
  c0.converged = true;
  c0.iterations = assemblyIterations_;
  c0.residual = maxAbs(linkage_.deformations(x0_));
  KinematicState prev = makeState(0, settings_.start, x0_, c0);
  int prevSign = transferFunctions(x0_).determinantSign;
  if (const std::string bad = firstOutOfRange(prev); !bad.empty()) {
    stopAtOutOfRange(summary, prev, bad, nullptr);
    summary.stepsCompleted = 0;
    summary.alphaReached = settings_.start;
    summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return summary;
  }
  onStep(prev);
  summary.stepsCompleted = 1;
  summary.alphaReached = prev.alpha;
  summary.maxResidual = prev.residual;
  long total = 0;

  for (int k = 1; k <= settings_.steps; ++k) {
    const double alpha = settings_.start + k * h;
    pollStop(alpha);  // core/stop_request.hpp
    const double da = alpha - prev.alpha;
    VecX X = prev.x + da * prev.xp + 0.5 * da * da * prev.xpp;  // Doc000, eq. 26
    MatX frozen;
    if (settings_.corrector == CorrectorKind::ModifiedNewton) frozen = unknownJacobian(prev.x);
    const Correction c =
        correct(alpha, X, settings_.corrector == CorrectorKind::ModifiedNewton ? &frozen : nullptr);
    TransferFunctions tf;
    if (c.converged) tf = transferFunctions(X);
    const bool regular = c.converged && tf.rcond >= settings_.singularTolerance && tf.determinantSign == prevSign;
    if (!regular) {
      const SingularPosition s = locate(prev, alpha, !c.converged);
      summary.ok = false;
      summary.singular = s;
      const double deg = s.alpha * 180.0 / M_PI;
      summary.message =
          std::string(s.kind == "lock" ? "the mechanism locks" : "change point") +
          " at input alpha = " + fmt(s.alpha, kNumberDigits) + " (" + fmt(deg, 7) + " deg): D L1 is singular there" +
          (s.kind == "lock" ? ", no position exists beyond" : ", two branches cross") + "; nodes " +
          joinQuoted(s.nodes) + ", links " + joinQuoted(s.links) + " (a lock, dead or change point);" +
          " results kept up to alpha = " + fmt(prev.alpha, kNumberDigits) + " (step " + std::to_string(prev.step) + ")";
      break;
    }
    KinematicState state = makeState(k, alpha, X, c);
    if (const std::string bad = firstOutOfRange(state); !bad.empty()) {
      stopAtOutOfRange(summary, state, bad, &prev);
      break;
    }
    prevSign = tf.determinantSign;
    onStep(state);
    summary.stepsCompleted = k + 1;
    summary.alphaReached = alpha;
    summary.maxResidual = std::max(summary.maxResidual, state.residual);
    summary.minIterations = k == 1 ? state.iterations : std::min(summary.minIterations, state.iterations);
    summary.maxIterations = std::max(summary.maxIterations, state.iterations);
    total += state.iterations;
    prev = std::move(state);
  }
  if (summary.stepsCompleted > 1) summary.meanIterations = static_cast<double>(total) / (summary.stepsCompleted - 1);
  if (summary.ok) {
    summary.message = "reached alpha = " + fmt(summary.alphaReached, kNumberDigits) + " in " +
                      std::to_string(settings_.steps) + " steps";
  }
  summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

KinematicSummary analyzeKinematics(const Linkage2d& linkage, const KinematicSettings& settings,
                                   const std::function<void(const KinematicState&)>& onStep) {
  return KinematicAnalysis(linkage, settings).run(onStep);
}

std::vector<std::string> kinematicsColumns(const Linkage2d& linkage) {
  std::vector<std::string> c = {"step", "alpha", "iterations", "residual", "rcond"};
  for (int i = 0; i < linkage.numInputs(); ++i) c.push_back(linkage.input(InputIndex(i)).name);
  for (int i = 0; i < linkage.numNodes(); ++i) {
    const std::string& n = linkage.node(NodeIndex(i)).name;
    for (const char* k : {".x", ".y", ".dx_da", ".dy_da", ".d2x_da2", ".d2y_da2", ".vx", ".vy", ".ax", ".ay"}) {
      c.push_back(n + k);
    }
  }
  for (int k = 0; k < linkage.numLinks(); ++k) {
    const std::string& n = linkage.link(LinkIndex(k)).name;
    for (const char* e : {".angle", ".dangle_da", ".d2angle_da2", ".omega", ".omega_dot"}) c.push_back(n + e);
  }
  return c;
}

void kinematicsRow(const Linkage2d& linkage, const KinematicState& s, std::vector<double>& values) {
  values.clear();
  values.insert(values.end(), {static_cast<double>(s.step), s.alpha, static_cast<double>(s.iterations), s.residual,
                               s.rcond});
  for (int i = 0; i < linkage.numInputs(); ++i) values.push_back(s.x[linkage.input(InputIndex(i)).coordinate]);
  for (int i = 0; i < linkage.numNodes(); ++i) {
    const NodeIndex n(i);
    const Vec2 r = linkage.nodePosition(n, s.x), rp = linkage.nodeDerivative(n, s.xp),
               rpp = linkage.nodeDerivative(n, s.xpp), v = linkage.nodeDerivative(n, s.v),
               a = linkage.nodeDerivative(n, s.a);
    for (const Vec2* p : {&r, &rp, &rpp, &v, &a}) values.insert(values.end(), {p->x(), p->y()});
  }
  for (int k = 0; k < linkage.numLinks(); ++k) {
    const int c = linkage.link(LinkIndex(k)).offset;  // beta1: the link's angle when rigid
    values.insert(values.end(), {s.x[c], s.xp[c], s.xpp[c], s.v[c], s.a[c]});
  }
}

}  // namespace flexmbd
