#include "core/system_evaluation.hpp"

#include "core/linear_algebra.hpp"

#include <cmath>

namespace flexmbd {
namespace {

VecX gather(const std::vector<int>& cols, const VecX& x) {
  VecX out;
  flexmbd::gather(cols, x.data(), out);
  return out;
}

/// Calls fn(index, constraint, evaluation, f, f', f'') for every constraint at (q, t).
template <class Fn>
void forEachConstraint(const System& sys, const VecX& q, double t, bool withHessians, Fn&& fn) {
  ConstraintEvaluation ev;
  VecX f, df, ddf;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    con.evaluate(sys.constraintStates(ci, q.data()), withHessians, ev);
    con.timeFunction(t, f, df, ddf);
    fn(ci, con, ev, f, df, ddf);
  }
}

}  // namespace

void evaluateConstraints(const System& sys, const VecX& q, double t, VecX* g, MatX* G) {
  const int m = sys.numConstraintEquations();
  if (g) g->setZero(m);
  if (G) G->setZero(m, sys.numVelocities());
  forEachConstraint(sys, q, t, false, [&](ConstraintIndex ci, const Constraint& con, const ConstraintEvaluation& ev,
                                          const VecX& f, const VecX&, const VecX&) {
    const int row = sys.constraintOffset(ci), me = con.numEquations();
    if (g) {
      g->segment(row, me) = ev.h - f;
      // an angle known modulo a period: the residual on the branch nearest f
      if (const double period = con.equationPeriod(); period > 0.0) {
        for (int a = 0; a < me; ++a) (*g)[row + a] = std::remainder((*g)[row + a], period);
      }
    }
    if (G) {
      const auto& cols = sys.constraintColumns(ci);
      for (size_t k = 0; k < cols.size(); ++k) G->block(row, cols[k], me, 1) += ev.G.col(k);
    }
  });
}

VecX velocityConstraintResidual(const System& sys, const VecX& q, const VecX& v, double t) {
  VecX out(sys.numConstraintEquations());
  forEachConstraint(sys, q, t, false, [&](ConstraintIndex ci, const Constraint& con, const ConstraintEvaluation& ev,
                                          const VecX&, const VecX& df, const VecX&) {
    out.segment(sys.constraintOffset(ci), con.numEquations()) = ev.G * gather(sys.constraintColumns(ci), v) - df;
  });
  return out;
}

VecX accelerationConstraintRhs(const System& sys, const VecX& q, const VecX& v, double t) {
  VecX out(sys.numConstraintEquations());
  const VecX Tv = sys.coordinateRates(q, v);  // q'
  forEachConstraint(sys, q, t, true, [&](ConstraintIndex ci, const Constraint& con, const ConstraintEvaluation& ev,
                                         const VecX&, const VecX&, const VecX& ddf) {
    const VecX vl = gather(sys.constraintColumns(ci), v), wl = gather(sys.constraintCoordinateColumns(ci), Tv);
    const int row = sys.constraintOffset(ci);
    for (int a = 0; a < con.numEquations(); ++a) out[row + a] = ddf[a] - vl.dot(ev.H[a] * wl);
  });
  return out;
}

namespace {

/// [M G^T; G 0] at q through `sinkAt(row0, col0)` (a MatrixSink at that offset): each body
/// writes its mass matrix's structural non-zeros, each constraint its G block.
template <class SinkAt>
void addAugmentedMatrix(const System& sys, const VecX& q, SinkAt&& sinkAt) {
  const int n = sys.numVelocities();
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    if (body.numCoordinates() == 0) continue;
    const int voff = sys.velocityOffset(bi);
    body.addMassMatrix(q.segment(sys.coordinateOffset(bi), body.numCoordinates()), sinkAt(voff, voff));
  }
  const MatrixSink A = sinkAt(0, 0);
  forEachConstraint(sys, q, 0.0, false, [&](ConstraintIndex ci, const Constraint& con, const ConstraintEvaluation& ev,
                                            const VecX&, const VecX&, const VecX&) {
    const auto& cols = sys.constraintColumns(ci);
    const int row = n + sys.constraintOffset(ci);
    for (size_t k = 0; k < cols.size(); ++k) {
      for (int a = 0; a < con.numEquations(); ++a) {
        const double g = ev.G(a, static_cast<Eigen::Index>(k));
        if (g == 0.0) continue;
        A.add(row + a, cols[k], g);
        A.add(cols[k], row + a, g);
      }
    }
  });
}

}  // namespace

SpMat augmentedMatrix(const System& sys, const VecX& q) {
  const int size = sys.numVelocities() + sys.numConstraintEquations();
  std::vector<Eigen::Triplet<double>> entries;
  JacobianSink sink = JacobianSink::recorder(&entries);
  addAugmentedMatrix(sys, q, [&](int r, int c) { return MatrixSink(sink, r, c); });
  SpMat A(size, size);
  A.setFromTriplets(entries.begin(), entries.end());  // duplicates summed
  return A;
}

MatX denseAugmentedMatrix(const System& sys, const VecX& q) {
  const int size = sys.numVelocities() + sys.numConstraintEquations();
  MatX A = MatX::Zero(size, size);
  addAugmentedMatrix(sys, q, [&](int r, int c) { return MatrixSink(A, r, c); });
  return A;
}

MatX massMatrix(const System& sys, const VecX& q) {
  const int n = sys.numVelocities();
  MatX M = MatX::Zero(n, n);
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int nqb = body.numCoordinates(), nvb = body.numVelocities();
    if (nqb == 0) continue;
    const int voff = sys.velocityOffset(bi);
    M.block(voff, voff, nvb, nvb) = body.massMatrix(q.segment(sys.coordinateOffset(bi), nqb));
  }
  return M;
}

VecX generalizedForces(const System& sys, double t, const VecX& q, const VecX& v) {
  VecX Q = VecX::Zero(sys.numVelocities());
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int nqb = body.numCoordinates(), nvb = body.numVelocities();
    if (nqb == 0) continue;
    const int qoff = sys.coordinateOffset(bi), voff = sys.velocityOffset(bi);
    VecX Qb = VecX::Zero(nvb);
    body.addInternalForces(q.segment(qoff, nqb), v.segment(voff, nvb), Qb);
    body.addGravityForce(q.segment(qoff, nqb), sys.gravity(), Qb);
    Q.segment(voff, nvb) += Qb;
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    const ForceIndex fi(f);
    const Force& force = sys.force(fi);
    const auto& cols = sys.forceColumns(fi);
    VecX Ql = VecX::Zero(cols.size());
    force.addForce(t, sys.forceStates(fi, q.data()), gather(cols, v), Ql, nullptr, nullptr);
    for (size_t k = 0; k < cols.size(); ++k) Q[cols[k]] += Ql[k];
  }
  return Q;
}

double kineticEnergy(const System& sys, const VecX& q, const VecX& v) {
  VecX Mv = VecX::Zero(v.size());
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int voff = sys.velocityOffset(bi), nvb = body.numVelocities();
    body.addMassTimes(q.segment(sys.coordinateOffset(bi), body.numCoordinates()), v.segment(voff, nvb),
                      Mv.segment(voff, nvb));
  }
  return 0.5 * v.dot(Mv);
}

double potentialEnergy(const System& sys, const VecX& q) {
  double V = 0.0;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int nb = body.numCoordinates();
    if (nb == 0) continue;
    const auto qb = q.segment(sys.coordinateOffset(BodyIndex(b)), nb);
    V += body.gravityPotential(qb, sys.gravity()) + body.internalPotential(qb);
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    const ForceIndex fi(f);
    V += sys.force(fi).potentialEnergy(sys.forceStates(fi, q.data()));
  }
  return V;
}

bool isConservative(const System& sys) {
  for (int c = 0; c < sys.numConstraints(); ++c) {
    if (sys.constraint(ConstraintIndex(c)).isDriver()) return false;
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    if (!sys.force(ForceIndex(f)).isConservative()) return false;
  }
  for (int b = 0; b < sys.numBodies(); ++b) {
    if (sys.body(BodyIndex(b)).isDissipative()) return false;
  }
  return true;
}

VecX reactionOutputs(const System& sys, const VecX& q, const VecX& lambda) {
  std::vector<double> out;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const VecX r = con.reactions(sys.constraintStates(ci, q.data()),
                                 lambda.segment(sys.constraintOffset(ci), con.numEquations()));
    out.insert(out.end(), r.data(), r.data() + r.size());
  }
  return Eigen::Map<VecX>(out.data(), static_cast<Eigen::Index>(out.size()));
}

std::vector<std::string> reactionOutputNames(const System& sys) {
  std::vector<std::string> names;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const Constraint& con = sys.constraint(ConstraintIndex(c));
    for (const auto& r : con.reactionNames()) names.push_back(con.name() + "." + r);
  }
  return names;
}

}  // namespace flexmbd
