#include "core/dae_system.hpp"

#include "core/errors.hpp"

namespace flexmbd {
namespace {

using ConstMap = Eigen::Map<const VecX>;

/// out[k] = x[cols[k]]
void gather(const std::vector<int>& cols, const double* x, VecX& out) {
  out.resize(static_cast<Eigen::Index>(cols.size()));
  for (size_t k = 0; k < cols.size(); ++k) out[k] = x[cols[k]];
}

/// (column k of G) . x
double columnDot(const MatX& G, int k, const double* x) {
  const double* g = G.data() + static_cast<Eigen::Index>(k) * G.rows();
  double s = 0.0;
  for (Eigen::Index a = 0; a < G.rows(); ++a) s += g[a] * x[a];
  return s;
}

/// J(rowOffset + rows[i], colOffset + cols[j]) += B(i, j)
void addBlock(JacobianSink& J, int rowOffset, const std::vector<int>& rows, int colOffset,
              const std::vector<int>& cols, const MatX& B) {
  for (size_t j = 0; j < cols.size(); ++j) {
    for (size_t i = 0; i < rows.size(); ++i) J.add(rowOffset + rows[i], colOffset + cols[j], B(i, j));
  }
}

/// J(row0 + i, colOffset + cols[j]) += B(i, j): a block on consecutive rows (constraint
/// equations), one merge walk per column.
void addRowsBlock(JacobianSink& J, int row0, int colOffset, const std::vector<int>& cols, const MatX& B) {
  for (size_t j = 0; j < cols.size(); ++j) {
    J.addColumn(colOffset + cols[j], row0, nullptr, B.col(static_cast<Eigen::Index>(j)).data(),
                static_cast<int>(B.rows()), 1.0);
  }
}

/// Working memory of one constraint's terms.
struct ConstraintScratch {
  ConstraintEvaluation ev, plus, minus;  ///< at q; at q +- h e_k (index-1 third derivatives)
  VecX f, df, ddf;                       ///< prescribed motion and its derivatives
  VecX vl, al, Hv;                       ///< local velocities, accelerations, H_a v
  MatX Hx, vH, dFdq;                     ///< sum_a x_a H_a, rows v^T H_a, index-1 d/dq
};

/// Working memory of one force element.
struct ForceScratch {
  KinematicsWork work;
  VecX vl, Q;
  MatX dQdq, dQdv;
};

/// DaeSystem's scratch: one per integrator, so that evaluations allocate nothing.
struct DaeSystemScratch final : DaeScratch {
  std::vector<VecX> bodyForce;  ///< per body, its generalised forces
  std::vector<ConstraintScratch> constraints;
  std::vector<ForceScratch> forces;
  VecX qPlus, qMinus;           ///< perturbed coordinates (index-1 Jacobian)
};

DaeSystemScratch& scratchOf(DaeScratch& s) {
  auto* d = dynamic_cast<DaeSystemScratch*>(&s);
  if (!d) throw std::logic_error("DaeSystem: the scratch was not made by DaeSystem::makeScratch()");
  return *d;
}

}  // namespace

std::string toString(Formulation f) {
  switch (f) {
    case Formulation::Ggl: return "ggl";
    case Formulation::Index3: return "index3";
    case Formulation::Index1: return "index1";
  }
  return "?";
}

Formulation parseFormulation(const std::string& name) {
  if (name == "ggl") return Formulation::Ggl;
  if (name == "index3") return Formulation::Index3;
  if (name == "index1") return Formulation::Index1;
  throw InputError("solver.formulation: unknown formulation '" + name +
                   "' (expected one of: ggl, index3, index1)");
}

VecX defaultStabilisationMetric(const System& sys) {
  if (!sys.isFinalized()) throw InputError("DaeSystem: the system must be finalized first");
  VecX D = VecX::Ones(sys.numCoordinates());
  const std::vector<CoordinateKind> kinds = sys.coordinateKinds();
  for (int k = 0; k < D.size(); ++k) {
    if (kinds[k] == CoordinateKind::Elastic) D[k] = kElasticStabilisationWeight;
  }
  return D;
}

DaeSystem::DaeSystem(const System& sys, Formulation formulation)
    : DaeSystem(sys, formulation, defaultStabilisationMetric(sys)) {}

DaeSystem::DaeSystem(const System& sys, Formulation formulation, VecX stabilisationMetric)
    : sys_(sys), formulation_(formulation), metric_(std::move(stabilisationMetric)) {
  if (!sys.isFinalized()) throw InputError("DaeSystem: the system must be finalized first");
  if (metric_.size() != sys.numCoordinates() || !(metric_.minCoeff() > 0.0) || !metric_.allFinite()) {
    throw InputError("DaeSystem: the stabilisation metric must have one positive entry per coordinate");
  }
  DaeLayout& L = layout_;
  L.nq = sys.numCoordinates();
  L.m = sys.numConstraintEquations();
  L.q = 0;
  L.v = L.nq;
  L.lambda = 2 * L.nq;
  L.mu = formulation == Formulation::Ggl ? 2 * L.nq + L.m : -1;
  L.size = 2 * L.nq + (formulation == Formulation::Ggl ? 2 : 1) * L.m;

  // The pattern is what the assembly writes, recorded once at the initial state.
  std::vector<std::pair<int, int>> entries;
  JacobianSink recorder = JacobianSink::recorder(&entries);
  VecX y, yp;
  const VecX q0 = sys.initialCoordinates();
  packState(q0, VecX::Zero(L.nq), VecX::Zero(L.nq), VecX::Zero(L.m), y, yp);
  jacobian(0.0, y.data(), yp.data(), 1.0, recorder);
  pattern_ = SparsePattern(L.size, std::move(entries));
}

VecX DaeSystem::differentialIds() const {
  VecX id = VecX::Zero(layout_.size);
  id.segment(layout_.q, layout_.nq).setOnes();
  if (formulation_ != Formulation::Index3) id.segment(layout_.v, layout_.nq).setOnes();
  return id;
}

std::vector<int64_t> DaeSystem::eliminationGroups() const {
  const DaeLayout& L = layout_;
  std::vector<int64_t> groups(L.size, 0);
  for (int k = 2 * L.nq; k < L.size; ++k) groups[k] = 1;
  for (int f : sys_.frameCoordinates()) groups[L.q + f] = groups[L.v + f] = 1;
  return groups;
}

std::unique_ptr<DaeScratch> DaeSystem::makeScratch() const {
  const System& sys = sys_;
  auto s = std::make_unique<DaeSystemScratch>();
  for (int b = 0; b < sys.numBodies(); ++b) s->bodyForce.emplace_back(sys.body(BodyIndex(b)).numCoordinates());
  s->constraints.resize(sys.numConstraints());
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const int nl = static_cast<int>(sys.constraintColumns(ci).size()), me = sys.constraint(ci).numEquations();
    ConstraintScratch& cs = s->constraints[c];
    cs.vl.resize(nl);
    cs.al.resize(nl);
    cs.Hv.resize(nl);
    cs.Hx.resize(nl, nl);
    cs.vH.resize(me, nl);
    cs.dFdq.resize(me, nl);
  }
  s->forces.resize(sys.numForces());
  for (int f = 0; f < sys.numForces(); ++f) {
    const int nl = static_cast<int>(sys.forceColumns(ForceIndex(f)).size());
    ForceScratch& fs = s->forces[f];
    fs.vl.resize(nl);
    fs.Q.resize(nl);
    fs.dQdq.resize(nl, nl);
    fs.dQdv.resize(nl, nl);
  }
  s->qPlus.resize(sys.numCoordinates());
  s->qMinus.resize(sys.numCoordinates());
  return s;
}

void DaeSystem::packState(const VecX& q, const VecX& v, const VecX& a, const VecX& lambda,
                          VecX& y, VecX& yp) const {
  const DaeLayout& L = layout_;
  y = VecX::Zero(L.size);
  yp = VecX::Zero(L.size);
  y.segment(L.q, L.nq) = q;
  y.segment(L.v, L.nq) = v;
  y.segment(L.lambda, L.m) = lambda;
  yp.segment(L.q, L.nq) = v;
  yp.segment(L.v, L.nq) = a;
}

void DaeSystem::residual(double t, const double* y, const double* yp, double* F, DaeScratch& scratch) const {
  const DaeLayout& L = layout_;
  const System& sys = sys_;
  DaeSystemScratch& S = scratchOf(scratch);
  ConstMap q(y + L.q, L.nq), v(y + L.v, L.nq), qp(yp + L.q, L.nq), vp(yp + L.v, L.nq);
  Eigen::Map<VecX> Fq(F + L.q, L.nq), Fv(F + L.v, L.nq);
  Fq = qp - v;
  Fv.setZero();
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int nb = body.numCoordinates();
    if (nb == 0) continue;
    const int off = sys.coordinateOffset(BodyIndex(b));
    const auto qb = q.segment(off, nb);
    VecX& Qb = S.bodyForce[b];
    Qb.setZero();
    body.addInternalForces(qb, v.segment(off, nb), Qb);
    body.addGravityForce(qb, sys.gravity(), Qb);
    Fv.segment(off, nb) -= Qb;
    body.addMassTimes(qb, vp.segment(off, nb), Fv.segment(off, nb));
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    const ForceIndex fi(f);
    const auto& cols = sys.forceColumns(fi);
    ForceScratch& fs = S.forces[f];
    gather(cols, v.data(), fs.vl);
    fs.Q.setZero();
    sys.force(fi).addForce(t, sys.forceStates(fi, q.data()), fs.vl, fs.Q, nullptr, nullptr, fs.work);
    for (size_t k = 0; k < cols.size(); ++k) Fv[cols[k]] -= fs.Q[k];
  }
  const bool needH = formulation_ == Formulation::Index1;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const int row = sys.constraintOffset(ci), me = con.numEquations(), nl = static_cast<int>(cols.size());
    ConstraintScratch& cs = S.constraints[c];
    const ConstraintEvaluation& ev = cs.ev;
    con.evaluate(sys.constraintStates(ci, q.data()), needH, cs.ev);
    con.timeFunction(t, cs.f, cs.df, cs.ddf);
    // F_v += G^T lambda (G is m_c x n_c, a few entries: plain loops beat Eigen's GEMV)
    const double* lambda = y + L.lambda + row;
    for (int k = 0; k < nl; ++k) Fv[cols[k]] += columnDot(ev.G, k, lambda);
    Eigen::Map<VecX> Fc(F + L.lambda + row, me);
    switch (formulation_) {
      case Formulation::Ggl: {
        // F_q += D G^T mu;  F_g = h - f;  F_gv = G v - f'
        const double* mu = y + L.mu + row;
        for (int k = 0; k < nl; ++k) Fq[cols[k]] += metric_[cols[k]] * columnDot(ev.G, k, mu);
        Fc = ev.h - cs.f;
        double* Fcv = F + L.mu + row;
        for (int a = 0; a < me; ++a) Fcv[a] = -cs.df[a];
        for (int k = 0; k < nl; ++k) {
          const double vk = v[cols[k]];
          for (int a = 0; a < me; ++a) Fcv[a] += ev.G(a, k) * vk;
        }
        break;
      }
      case Formulation::Index3:
        Fc = ev.h - cs.f;
        break;
      case Formulation::Index1: {
        // F_a = G a + v^T H_a v - f''
        gather(cols, v.data(), cs.vl);
        gather(cols, vp.data(), cs.al);
        for (int a = 0; a < me; ++a) {
          cs.Hv.noalias() = ev.H[a] * cs.vl;
          Fc[a] = ev.G.row(a).dot(cs.al) + cs.vl.dot(cs.Hv) - cs.ddf[a];
        }
        break;
      }
    }
  }
}

void DaeSystem::jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                         DaeScratch& scratch) const {
  const DaeLayout& L = layout_;
  const System& sys = sys_;
  DaeSystemScratch& S = scratchOf(scratch);
  ConstMap q(y + L.q, L.nq), v(y + L.v, L.nq), vp(yp + L.v, L.nq);
  // F_q = q' - v (+ G^T mu): dF_q/dq' = I, dF_q/dv = -I
  for (int k = 0; k < L.nq; ++k) {
    J.add(L.q + k, L.q + k, cj);
    J.add(L.q + k, L.v + k, -1.0);
  }
  // F_v = M v' - Q: d(M a)/dq - dQ/dq and cj M - dQ/dv, body by body
  for (int b = 0; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const int nb = body.numCoordinates();
    if (nb == 0) continue;
    const int off = sys.coordinateOffset(BodyIndex(b));
    const auto qb = q.segment(off, nb);
    // each body writes its structural non-zeros only (sparse for large flexible bodies)
    const MatrixSink Jq(J, L.v + off, L.q + off), minusJq(J, L.v + off, L.q + off, -1.0);
    const MatrixSink cjM(J, L.v + off, L.v + off, cj), minusJv(J, L.v + off, L.v + off, -1.0);
    body.addMassMatrixDerivative(qb, vp.segment(off, nb), Jq);
    body.addInternalForceJacobians(qb, v.segment(off, nb), minusJq, minusJv);
    body.addGravityJacobian(qb, sys.gravity(), minusJq);
    body.addMassMatrix(qb, cjM);
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    const ForceIndex fi(f);
    const auto& cols = sys.forceColumns(fi);
    ForceScratch& fs = S.forces[f];
    gather(cols, v.data(), fs.vl);
    fs.Q.setZero();
    fs.dQdq.setZero();
    fs.dQdv.setZero();
    sys.force(fi).addForce(t, sys.forceStates(fi, q.data()), fs.vl, fs.Q, &fs.dQdq, &fs.dQdv, fs.work);
    fs.dQdq *= -1.0;
    fs.dQdv *= -1.0;
    addBlock(J, L.v, cols, L.q, cols, fs.dQdq);
    addBlock(J, L.v, cols, L.v, cols, fs.dQdv);
  }
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const int nl = static_cast<int>(cols.size());
    const int row = sys.constraintOffset(ci), me = con.numEquations();
    ConstraintScratch& cs = S.constraints[c];
    const ConstraintEvaluation& ev = cs.ev;
    con.evaluate(sys.constraintStates(ci, q.data()), true, cs.ev);
    gather(cols, v.data(), cs.vl);
    // d(G^T lambda)/dq = sum_a lambda_a H_a, and dF_v/dlambda = G^T
    cs.Hx.setZero();
    for (int a = 0; a < me; ++a) cs.Hx += y[L.lambda + row + a] * ev.H[a];
    addBlock(J, L.v, cols, L.q, cols, cs.Hx);
    for (int a = 0; a < me; ++a) {
      for (int k = 0; k < nl; ++k) J.add(L.v + cols[k], L.lambda + row + a, ev.G(a, k));
    }
    for (int a = 0; a < me; ++a) cs.vH.row(a).noalias() = cs.vl.transpose() * ev.H[a];  // d(G v)/dq
    switch (formulation_) {
      case Formulation::Ggl: {
        // F_q += D G^T mu: d/dq = D sum_a mu_a H_a, d/dmu = D G^T
        cs.Hx.setZero();
        for (int a = 0; a < me; ++a) cs.Hx += y[L.mu + row + a] * ev.H[a];
        for (int j = 0; j < nl; ++j) {
          for (int i = 0; i < nl; ++i) J.add(L.q + cols[i], L.q + cols[j], metric_[cols[i]] * cs.Hx(i, j));
        }
        for (int a = 0; a < me; ++a) {
          for (int k = 0; k < nl; ++k) J.add(L.q + cols[k], L.mu + row + a, metric_[cols[k]] * ev.G(a, k));
        }
        addRowsBlock(J, L.lambda + row, L.q, cols, ev.G);
        addRowsBlock(J, L.mu + row, L.q, cols, cs.vH);
        addRowsBlock(J, L.mu + row, L.v, cols, ev.G);
        break;
      }
      case Formulation::Index3:
        addRowsBlock(J, L.lambda + row, L.q, cols, ev.G);
        break;
      case Formulation::Index1: {
        // F_a = G a + v^T H v - f'': d/dq = a^T H_a + d(v^T H_a v)/dq, d/dv = 2 v^T H_a,
        // d/da = G. The third-derivative term d(v^T H_a v)/dq is the one block taken
        // by central differences of the analytic Hessians (docs/formulations.md).
        gather(cols, vp.data(), cs.al);
        for (int a = 0; a < me; ++a) cs.dFdq.row(a).noalias() = cs.al.transpose() * ev.H[a];
        S.qPlus = q;
        S.qMinus = q;
        for (int k = 0; k < nl; ++k) {
          const int c = cols[k];
          const double h = 1e-6 * (1.0 + std::abs(q[c]));
          S.qPlus[c] = q[c] + h;
          S.qMinus[c] = q[c] - h;
          con.evaluate(sys.constraintStates(ci, S.qPlus.data()), true, cs.plus);
          con.evaluate(sys.constraintStates(ci, S.qMinus.data()), true, cs.minus);
          S.qPlus[c] = S.qMinus[c] = q[c];
          for (int a = 0; a < me; ++a) {
            cs.Hv.noalias() = cs.plus.H[a] * cs.vl;
            const double plus = cs.vl.dot(cs.Hv);
            cs.Hv.noalias() = cs.minus.H[a] * cs.vl;
            cs.dFdq(a, k) += (plus - cs.vl.dot(cs.Hv)) / (2.0 * h);
          }
        }
        addRowsBlock(J, L.lambda + row, L.q, cols, cs.dFdq);
        cs.vH *= 2.0;
        cs.vH += cj * ev.G;
        addRowsBlock(J, L.lambda + row, L.v, cols, cs.vH);
        break;
      }
    }
  }
}

}  // namespace flexmbd
