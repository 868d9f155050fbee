#include "core/dae_system.hpp"

#include "core/errors.hpp"

namespace flexmbd {
namespace {

using ConstMap = Eigen::Map<const VecX>;

VecX gather(const std::vector<int>& cols, const double* x) {
  VecX out(cols.size());
  for (size_t k = 0; k < cols.size(); ++k) out[k] = x[cols[k]];
  return out;
}

/// J(rowOffset + rows[i], colOffset + cols[j]) += B(i, j)
void addBlock(JacobianSink& J, int rowOffset, const std::vector<int>& rows, int colOffset,
              const std::vector<int>& cols, const MatX& B) {
  for (size_t j = 0; j < cols.size(); ++j) {
    for (size_t i = 0; i < rows.size(); ++i) J.add(rowOffset + rows[i], colOffset + cols[j], B(i, j));
  }
}

std::vector<int> range(int start, int n) {
  std::vector<int> r(n);
  for (int k = 0; k < n; ++k) r[k] = start + k;
  return r;
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

void DaeSystem::residual(double t, const double* y, const double* yp, double* F, DaeScratch&) const {
  const DaeLayout& L = layout_;
  const System& sys = sys_;
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
    VecX Qb = VecX::Zero(nb);
    body.addInternalForces(qb, v.segment(off, nb), Qb);
    body.addGravityForce(qb, sys.gravity(), Qb);
    Fv.segment(off, nb) -= Qb;
    body.addMassTimes(qb, vp.segment(off, nb), Fv.segment(off, nb));
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    const ForceIndex fi(f);
    const Force& force = sys.force(fi);
    const auto& cols = sys.forceColumns(fi);
    VecX Ql = VecX::Zero(cols.size());
    force.addForce(t, sys.forceStates(fi, q.data()), gather(cols, v.data()), Ql,
                   nullptr, nullptr);
    for (size_t k = 0; k < cols.size(); ++k) Fv[cols[k]] -= Ql[k];
  }
  ConstraintEvaluation ev;
  VecX f, df, ddf;
  const bool needH = formulation_ == Formulation::Index1;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const int row = sys.constraintOffset(ci), me = con.numEquations();
    con.evaluate(sys.constraintStates(ci, q.data()), needH, ev);
    con.timeFunction(t, f, df, ddf);
    const VecX GtLambda = ev.G.transpose() * ConstMap(y + L.lambda + row, me);
    for (size_t k = 0; k < cols.size(); ++k) Fv[cols[k]] += GtLambda[k];
    const VecX vl = gather(cols, v.data());
    switch (formulation_) {
      case Formulation::Ggl: {
        const VecX GtMu = ev.G.transpose() * ConstMap(y + L.mu + row, me);
        for (size_t k = 0; k < cols.size(); ++k) Fq[cols[k]] += metric_[cols[k]] * GtMu[k];
        Eigen::Map<VecX>(F + L.lambda + row, me) = ev.h - f;
        Eigen::Map<VecX>(F + L.mu + row, me) = ev.G * vl - df;
        break;
      }
      case Formulation::Index3:
        Eigen::Map<VecX>(F + L.lambda + row, me) = ev.h - f;
        break;
      case Formulation::Index1: {
        const VecX al = gather(cols, vp.data());
        for (int a = 0; a < me; ++a) {
          F[L.lambda + row + a] = ev.G.row(a).dot(al) + vl.dot(ev.H[a] * vl) - ddf[a];
        }
        break;
      }
    }
  }
}

void DaeSystem::jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                         DaeScratch&) const {
  const DaeLayout& L = layout_;
  const System& sys = sys_;
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
    const Force& force = sys.force(fi);
    const auto& cols = sys.forceColumns(fi);
    const int nl = static_cast<int>(cols.size());
    VecX Ql = VecX::Zero(nl);
    MatX dQdq = MatX::Zero(nl, nl), dQdv = MatX::Zero(nl, nl);
    force.addForce(t, sys.forceStates(fi, q.data()), gather(cols, v.data()), Ql, &dQdq,
                   &dQdv);
    addBlock(J, L.v, cols, L.q, cols, -dQdq);
    addBlock(J, L.v, cols, L.v, cols, -dQdv);
  }
  ConstraintEvaluation ev;
  VecX f, df, ddf;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const int nl = static_cast<int>(cols.size());
    const int row = sys.constraintOffset(ci), me = con.numEquations();
    const std::vector<int> rows = range(row, me);
    con.evaluate(sys.constraintStates(ci, q.data()), true, ev);
    const VecX vl = gather(cols, v.data());
    const MatX Gt = ev.G.transpose();
    // d(G^T lambda)/dq = sum_a lambda_a H_a, and dF_v/dlambda = G^T
    MatX Hl = MatX::Zero(nl, nl);
    for (int a = 0; a < me; ++a) Hl += y[L.lambda + row + a] * ev.H[a];
    addBlock(J, L.v, cols, L.q, cols, Hl);
    addBlock(J, L.v, cols, L.lambda, rows, Gt);
    MatX vH(me, nl);  // rows v^T H_a = d(G v)/dq
    for (int a = 0; a < me; ++a) vH.row(a) = vl.transpose() * ev.H[a];
    switch (formulation_) {
      case Formulation::Ggl: {
        MatX Hm = MatX::Zero(nl, nl);
        for (int a = 0; a < me; ++a) Hm += y[L.mu + row + a] * ev.H[a];
        MatX DGt = Gt;
        for (int k = 0; k < nl; ++k) {
          Hm.row(k) *= metric_[cols[k]];
          DGt.row(k) *= metric_[cols[k]];
        }
        addBlock(J, L.q, cols, L.q, cols, Hm);
        addBlock(J, L.q, cols, L.mu, rows, DGt);
        addBlock(J, L.lambda, rows, L.q, cols, ev.G);
        addBlock(J, L.mu, rows, L.q, cols, vH);
        addBlock(J, L.mu, rows, L.v, cols, ev.G);
        break;
      }
      case Formulation::Index3:
        addBlock(J, L.lambda, rows, L.q, cols, ev.G);
        break;
      case Formulation::Index1: {
        // F_a = G a + v^T H v - f'': d/dq = a^T H_a + d(v^T H_a v)/dq, d/dv = 2 v^T H_a,
        // d/da = G. The third-derivative term d(v^T H_a v)/dq is the one block taken
        // by central differences of the analytic Hessians (docs/formulations.md).
        const VecX al = gather(cols, vp.data());
        MatX dFdq(me, nl);
        for (int a = 0; a < me; ++a) dFdq.row(a) = al.transpose() * ev.H[a];
        VecX qp = q, qm = q;
        ConstraintEvaluation ep, em;
        for (int k = 0; k < nl; ++k) {
          const int c = cols[k];
          const double h = 1e-6 * (1.0 + std::abs(q[c]));
          qp[c] = q[c] + h;
          qm[c] = q[c] - h;
          con.evaluate(sys.constraintStates(ci, qp.data()), true, ep);
          con.evaluate(sys.constraintStates(ci, qm.data()), true, em);
          qp[c] = qm[c] = q[c];
          for (int a = 0; a < me; ++a) {
            dFdq(a, k) += (vl.dot(ep.H[a] * vl) - vl.dot(em.H[a] * vl)) / (2.0 * h);
          }
        }
        addBlock(J, L.lambda, rows, L.q, cols, dFdq);
        addBlock(J, L.lambda, rows, L.v, cols, 2.0 * vH + cj * ev.G);
        break;
      }
    }
  }
}

}  // namespace flexmbd
