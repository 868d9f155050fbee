#include "core/dae_system.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/stop_request.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"

namespace flexmbd {
namespace {

using ConstMap = Eigen::Map<const VecX>;


/// (column k of G) . x
double columnDot(const MatX& G, int k, const double* x) {
  const double* g = G.data() + static_cast<Eigen::Index>(k) * G.rows();
  double s = 0.0;
  for (Eigen::Index a = 0; a < G.rows(); ++a) s += g[a] * x[a];
  return s;
}

/// The GGL residual's terms of one constraint in one pass over the columns k of its G
/// (m x n, column-major): Fv[c_k] += G_k . lambda, DGtmu[c_k] += D_c G_k . mu, Fcv += G_k v_c.
/// Each sum in the order of the separate loops it replaces (the same round-off).
struct GglColumns {
  const double* G;
  const int* cols;
  int n;
  const double *lambda, *mu, *v, *metric;
  double *Fv, *DGtmu, *Fcv;
  /// M: the number of equations m if known at compile time (unrolled, kept in registers), else 0.
  template <int M>
  void run(int m) const {
    constexpr int kCap = M > 0 ? M : 1;
    if (M == 0) {
      const double* g = G;
      for (int k = 0; k < n; ++k, g += m) {
        const int c = cols[k];
        double gl = 0.0, gm = 0.0;
        for (int a = 0; a < m; ++a) {
          gl += g[a] * lambda[a];
          gm += g[a] * mu[a];
          Fcv[a] += g[a] * v[c];
        }
        Fv[c] += gl;
        DGtmu[c] += metric[c] * gm;
      }
      return;
    }
    double l[kCap], u[kCap], f[kCap];
    for (int a = 0; a < M; ++a) {
      l[a] = lambda[a];
      u[a] = mu[a];
      f[a] = Fcv[a];
    }
    const double* g = G;
    for (int k = 0; k < n; ++k, g += M) {
      const int c = cols[k];
      const double vk = v[c];
      double gl = 0.0, gm = 0.0;
      for (int a = 0; a < M; ++a) {
        gl += g[a] * l[a];
        gm += g[a] * u[a];
        f[a] += g[a] * vk;
      }
      Fv[c] += gl;
      DGtmu[c] += metric[c] * gm;
    }
    for (int a = 0; a < M; ++a) Fcv[a] = f[a];
  }
};

/// Global indices of a constraint's or force's columns in ascending order, with where
/// each comes from: the rows of its blocks, written by one merge walk per column
/// (a constraint's columns are ascending within a body, not across its bodies).
struct SortedIndex {
  std::vector<int> sorted;  ///< ascending
  std::vector<int> from;    ///< sorted[i] = idx[from[i]]
  explicit SortedIndex(const std::vector<int>& idx = {}) : sorted(idx.size()), from(idx.size()) {
    for (size_t i = 0; i < idx.size(); ++i) from[i] = static_cast<int>(i);
    std::sort(from.begin(), from.end(), [&](int a, int b) { return idx[a] < idx[b]; });
    for (size_t i = 0; i < idx.size(); ++i) sorted[i] = idx[from[i]];
  }
  int size() const { return static_cast<int>(sorted.size()); }
};

/// J(rowOffset + rows[i], colOffset + cols[j]) += s B(i, j) (rows: the sorted rows), one
/// merge walk per column; `buf` holds a column (rows.size()).
template <class ColumnOf>
void addBlockColumns(JacobianSink& J, int rowOffset, const SortedIndex& rows, ColumnOf&& columnOf, const MatX& B,
                     VecX& buf, double s) {
  const int n = rows.size();
  for (Eigen::Index j = 0; j < B.cols(); ++j) {
    const double* b = B.data() + j * B.rows();
    for (int i = 0; i < n; ++i) buf[i] = b[rows.from[i]];
    J.addColumn(columnOf(static_cast<int>(j)), rowOffset, rows.sorted.data(), buf.data(), n, s);
  }
}
void addBlock(JacobianSink& J, int rowOffset, const SortedIndex& rows, int colOffset, const std::vector<int>& cols,
              const MatX& B, VecX& buf, double s = 1.0) {
  addBlockColumns(J, rowOffset, rows, [&](int j) { return colOffset + cols[j]; }, B, buf, s);
}
/// The same with the columns col0, col0 + 1, ... (multiplier columns).
void addBlock(JacobianSink& J, int rowOffset, const SortedIndex& rows, int col0, const MatX& B, VecX& buf,
              double s = 1.0) {
  addBlockColumns(J, rowOffset, rows, [&](int j) { return col0 + j; }, B, buf, s);
}

/// J(rowOffset + rows[i], col0 + a) += s B(a, i) for the rows a of B (m x rows): the
/// transpose of a row block (G^T), one merge walk per column.
void addTransposedBlock(JacobianSink& J, int rowOffset, const SortedIndex& rows, int col0, const MatX& B, VecX& buf,
                        double s = 1.0) {
  const int n = rows.size();
  for (Eigen::Index a = 0; a < B.rows(); ++a) {
    for (int i = 0; i < n; ++i) buf[i] = B(a, rows.from[i]);
    J.addColumn(col0 + static_cast<int>(a), rowOffset, rows.sorted.data(), buf.data(), n, s);
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
  VecX vl, al, Hv, wl, wlMinus;          ///< local velocities, accelerations, H_a w, (T v) local (and at q - h e_k)
  MatX Hx, vH, dFdq, dFdv;               ///< sum_a x_a H_a, rows v^T H_a, index-1 d/dq and d/dv
  MatX Tl, Til, THx, TGt, TDG;           ///< T and T+ over the local columns (T != I only), products
  SortedIndex vRows, qRows;              ///< the local velocity / coordinate columns, ascending
  VecX column;                           ///< one column of a block being written
};

/// Working memory of one force element.
struct ForceScratch {
  KinematicsWork work;
  VecX vl, Q;
  MatX dQdq, dQdv;
  SortedIndex vRows;  ///< the local velocity columns, ascending
  VecX column;
};

/// DaeSystem's scratch: one per integrator, so that evaluations allocate nothing.
struct DaeSystemScratch final : DaeScratch {
  std::vector<VecX> bodyForce;  ///< per body, its generalised forces
  /// Per body the values of T(q) and T+(q) in DaeSystem's rate patterns (T != I only).
  std::vector<std::vector<double>> T, Tinv;
  std::vector<ConstraintScratch> constraints;
  std::vector<ForceScratch> forces;
  VecX qPlus, qMinus;           ///< perturbed coordinates (index-1 Jacobian)
  VecX DGtmu, w, Tv, TvPlus;    ///< D G^T mu and w = D G^T mu - v (nv); T v (nq)
  /// Where the Jacobian's entries go in the DAE's pattern, in assembly order (recorded by
  /// the first assembly, replayed by the next: no search per entry).
  JacobianPositions positions;
};

DaeSystemScratch& scratchOf(DaeScratch& s) {
  auto* d = dynamic_cast<DaeSystemScratch*>(&s);
  if (!d) throw std::logic_error("DaeSystem: the scratch was not made by DaeSystem::makeScratch()");
  return *d;
}

/// out = T(q) v body by body, into a vector of size nq (no allocation).
void coordinateRates(const System& sys, const double* q, const double* v, VecX& out) {
  out.setZero(sys.numCoordinates());
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    const int nqb = body.numCoordinates(), nvb = body.numVelocities();
    if (nqb == 0) continue;
    body.addCoordinateRate(Eigen::Map<const VecX>(q + sys.coordinateOffset(bi), nqb),
                           Eigen::Map<const VecX>(v + sys.velocityOffset(bi), nvb),
                           out.segment(sys.coordinateOffset(bi), nqb));
  }
}

/// Entry (row, col) of a matrix stored as `values` in `pattern` (0 outside it).
double entryOf(const SparsePattern& pattern, const std::vector<double>& values, int row, int col) {
  const int64_t k = pattern.find(row, col);
  return k < 0 ? 0.0 : values[k];
}

/// The pattern of what `write` adds into an n x n sink (recorded once, values ignored).
template <class Write>
SparsePattern recordPattern(int n, Write&& write) {
  std::vector<Eigen::Triplet<double>> written;
  JacobianSink recorder = JacobianSink::recorder(&written);
  write(MatrixSink(recorder, 0, 0));
  std::vector<std::pair<int, int>> entries;
  entries.reserve(written.size());
  for (const auto& e : written) entries.emplace_back(e.row(), e.col());
  return SparsePattern(n, std::move(entries));
}

/// values = the entries `write` adds, in `pattern` (zeroed first; allocation-free).
template <class Write>
void fillPattern(const SparsePattern& pattern, std::vector<double>& values, Write&& write) {
  std::fill(values.begin(), values.end(), 0.0);
  JacobianSink sink = JacobianSink::sparse(values.data(), pattern);
  write(MatrixSink(sink, 0, 0));
}

/// Tl (nq_l x nv_l) and Til (nv_l x nq_l): T and T+ of a constraint's bodies restricted to
/// its used coordinates and velocities, block by body slot (S.T, S.Tinv filled before).
void localRateMatrices(const System& sys, ConstraintIndex ci, const double* q, const DaeSystemScratch& S,
                       const std::vector<SparsePattern>& Tp, const std::vector<SparsePattern>& Tip, MatX& Tl,
                       MatX& Til) {
  const BodyStates states = sys.constraintStates(ci, q);
  int nql = 0, nvl = 0;
  for (int k = 0; k < states.size(); ++k) {
    nql += states[k].numUsedCoordinates();
    nvl += states[k].numUsed();
  }
  Tl.setZero(nql, nvl);
  Til.setZero(nvl, nql);
  int r = 0, c = 0;
  for (int k = 0; k < states.size(); ++k) {
    const BodyState& st = states[k];
    const int b = sys.constraint(ci).bodies()[k].value;
    const std::vector<int>& qc = *st.qcols;
    const std::vector<int>& vc = *st.cols;
    const bool identity = st.body.velocitiesAreCoordinateRates();  // S.T[b] is not filled then
    for (size_t i = 0; i < qc.size(); ++i) {
      for (size_t j = 0; j < vc.size(); ++j) {
        Tl(r + i, c + j) = identity ? (qc[i] == vc[j] ? 1.0 : 0.0) : entryOf(Tp[b], S.T[b], qc[i], vc[j]);
        Til(c + j, r + i) = identity ? (qc[i] == vc[j] ? 1.0 : 0.0) : entryOf(Tip[b], S.Tinv[b], vc[j], qc[i]);
      }
    }
    r += static_cast<int>(qc.size());
    c += static_cast<int>(vc.size());
  }
}

/// One constraint's columns, rows and scratch, as the Jacobian's stages read them.
struct ConstraintBlock {
  ConstraintIndex ci;
  const Constraint& con;
  const std::vector<int>& cols;
  const std::vector<int>& qcols;
  int nl, nql, row, me;
  ConstraintScratch& cs;
  const ConstraintEvaluation& ev;
};

/// The stages of DaeSystem::jacobian (the iteration matrix dF/dy + cj dF/dy'): bodies,
/// forces, constraints, released equations. `identityT`: every velocity is a coordinate
/// rate (planar models), where the T(q) terms compile away. Its members are the DAE's
/// data under the DAE's own names.
template <bool identityT>
class JacobianAssembly {
 public:
  /// What the DAE holds for the assembly.
  struct Model {
    const System& sys;
    const DaeLayout& layout;
    Formulation formulation;
    const VecX& metric;
    const std::vector<int>& released;
    const std::vector<std::vector<int>>& keptRows;
    const std::vector<char>& partial;
    const std::vector<SparsePattern>& ratePattern;
    const std::vector<SparsePattern>& rateInversePattern;
  };
  JacobianAssembly(const Model& m, DaeSystemScratch& scratch, JacobianSink& sink, double time, const double* y,
                   const double* yp, double cj)
      : sys(m.sys), L(m.layout), formulation_(m.formulation), metric_(m.metric), released_(m.released),
        keptRows_(m.keptRows), partial_(m.partial), ratePattern_(m.ratePattern),
        rateInversePattern_(m.rateInversePattern), S(scratch), J(sink), t(time), y(y), cj(cj), q(y + L.q, L.nq),
        v(y + L.v, L.nv), vp(yp + L.v, L.nv) {}

  void run() {
    bodyBlocks();
    forceBlocks();
    if (!identityT) {
      S.DGtmu.setZero();
      if (formulation_ == Formulation::Index1) coordinateRates(sys, q.data(), v.data(), S.Tv);
    }
    for (int c = 0; c < sys.numConstraints(); ++c) constraintRows(c);
    releasedAndRateRows();
  }

 private:
  /// F_v = M v' - Q: d(M a)/dq - dQ/dq and cj M - dQ/dv, body by body; F_q = q' - T w:
  /// cj I and -T (with T = I: -I).
  void bodyBlocks() {
    const bool withGravity = sys.gravity() != Vec3::Zero();  // else its terms are zero
    for (int b = 0; b < sys.numBodies(); ++b) {
      const BodyIndex bi(b);
      const int nqb = sys.numCoordinates(bi), nvb = sys.numVelocities(bi);
      if (nqb == 0) continue;
      const Body& body = sys.body(bi);
      const int qoff = sys.coordinateOffset(bi), voff = sys.velocityOffset(bi);
      const auto qb = q.segment(qoff, nqb);
      for (int k = 0; k < nqb; ++k) J.add(L.q + qoff + k, L.q + qoff + k, cj);
      if (identityT || body.velocitiesAreCoordinateRates()) {
        for (int k = 0; k < nqb; ++k) J.add(L.q + qoff + k, L.v + voff + k, -1.0);
      } else {
        fillPattern(ratePattern_[b], S.T[b], [&](const MatrixSink& T) { body.addCoordinateRateMatrix(qb, T); });
        fillPattern(rateInversePattern_[b], S.Tinv[b],
                    [&](const MatrixSink& T) { body.addCoordinateRateInverse(qb, T); });
        // -T into F_q's velocity columns, its structural non-zeros only
        const SparsePattern& Tp = ratePattern_[b];
        for (int j = 0; j < nvb; ++j) {
          for (int64_t k = Tp.colStart()[j]; k < Tp.colStart()[j + 1]; ++k) {
            J.add(L.q + qoff + static_cast<int>(Tp.rowIndex()[k]), L.v + voff + j, -S.T[b][k]);
          }
        }
      }
      // each body writes its structural non-zeros only (sparse for large flexible bodies)
      const MatrixSink Jq(J, L.v + voff, L.q + qoff), minusJq(J, L.v + voff, L.q + qoff, -1.0);
      const MatrixSink cjM(J, L.v + voff, L.v + voff, cj), minusJv(J, L.v + voff, L.v + voff, -1.0);
      body.addMassMatrixDerivative(qb, vp.segment(voff, nvb), Jq);
      body.addInternalForceJacobians(qb, v.segment(voff, nvb), minusJq, minusJv);
      if (withGravity) body.addGravityJacobian(qb, sys.gravity(), minusJq);
      body.addMassMatrix(qb, cjM);
    }
  }

  /// -dQ/dq and -dQ/dv of every force element.
  void forceBlocks() {
    for (int f = 0; f < sys.numForces(); ++f) {
      const ForceIndex fi(f);
      const auto& cols = sys.forceColumns(fi);
      const auto& qcols = sys.forceCoordinateColumns(fi);
      ForceScratch& fs = S.forces[f];
      gather(cols, v.data(), fs.vl);
      fs.Q.setZero();
      fs.dQdq.setZero();
      fs.dQdv.setZero();
      sys.force(fi).addForce(t, sys.forceStates(fi, q.data()), fs.vl, fs.Q, &fs.dQdq, &fs.dQdv, fs.work);
      addBlock(J, L.v, fs.vRows, L.q, qcols, fs.dQdq, fs.column, -1.0);
      addBlock(J, L.v, fs.vRows, L.v, cols, fs.dQdv, fs.column, -1.0);
    }
  }

  /// Constraint c's blocks of every formulation (d(G^T lambda)/dq and G^T), then those of
  /// its formulation's rows.
  void constraintRows(int c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const auto& qcols = sys.constraintCoordinateColumns(ci);
    ConstraintScratch& cs = S.constraints[c];
    const ConstraintEvaluation& ev = cs.ev;
    const ConstraintBlock block{ci, con, cols, qcols, static_cast<int>(cols.size()), static_cast<int>(qcols.size()),
                            sys.constraintOffset(ci), con.numEquations(), cs, ev};
    const int row = block.row, me = block.me;
    con.evaluate(sys.constraintStates(ci, q.data()), true, cs.ev);
    gather(cols, v.data(), cs.vl);
    if (!identityT) localRateMatrices(sys, ci, q.data(), S, ratePattern_, rateInversePattern_, cs.Tl, cs.Til);
    // d(G^T lambda)/dq = sum_a lambda_a H_a, and dF_v/dlambda = G^T
    cs.Hx.setZero();
    for (int a = 0; a < me; ++a) cs.Hx += y[L.lambda + row + a] * ev.H[a];
    addBlock(J, L.v, cs.vRows, L.q, qcols, cs.Hx, cs.column);
    addTransposedBlock(J, L.v, cs.vRows, L.lambda + row, ev.G, cs.column);
    for (int a = 0; a < me; ++a) cs.vH.row(a).noalias() = cs.vl.transpose() * ev.H[a];  // d(G v)/dq
    switch (formulation_) {
      case Formulation::Ggl: return gglRows(c, block);
      case Formulation::Index3:
        if (identityT) {
          addConstraintRows(J, c, L.lambda + row, L.q, cols, ev.G, cs.column);
        } else {
          cs.dFdq.noalias() = ev.G * cs.Til;
          addConstraintRows(J, c, L.lambda + row, L.q, qcols, cs.dFdq, cs.column);
        }
        return;
      case Formulation::Index1: return index1Rows(c, block);
    }
  }

  /// GGL, the stabilised index 2 of Gear, Gupta and Leimkuhler: F_q += T D G^T mu,
  /// F_g = h - f, F_mu = G v - f'.
  void gglRows(int c, const ConstraintBlock& block) {
    const auto& [ci, con, cols, qcols, nl, nql, row, me, cs, ev] = block;
    // F_q += T D G^T mu: d/dq = T D sum_a mu_a H_a (+ the dT/dq term below), d/dmu = T D G^T
    cs.Hx.setZero();
    for (int a = 0; a < me; ++a) cs.Hx += y[L.mu + row + a] * ev.H[a];
    if (identityT) {
      for (int k = 0; k < nl; ++k) cs.Hx.row(k) *= metric_[cols[k]];  // D sum_a mu_a H_a
      addBlock(J, L.q, cs.vRows, L.q, cols, cs.Hx, cs.column);
      cs.TGt.resize(nl, me);  // (D G^T)
      for (int k = 0; k < nl; ++k) cs.TGt.row(k) = metric_[cols[k]] * ev.G.col(k).transpose();
      addBlock(J, L.q, cs.vRows, L.mu + row, cs.TGt, cs.column);
      addConstraintRows(J, c, L.lambda + row, L.q, cols, ev.G, cs.column);
    } else {
      const double* mu = y + L.mu + row;
      for (int k = 0; k < nl; ++k) {
        cs.Hx.row(k) *= metric_[cols[k]];
        S.DGtmu[cols[k]] += metric_[cols[k]] * columnDot(ev.G, k, mu);
      }
      cs.THx.noalias() = cs.Tl * cs.Hx;
      addBlock(J, L.q, cs.qRows, L.q, qcols, cs.THx, cs.column);
      cs.TGt.resize(nl, me);
      for (int k = 0; k < nl; ++k) cs.TGt.row(k) = metric_[cols[k]] * ev.G.col(k).transpose();
      cs.TDG.noalias() = cs.Tl * cs.TGt;  // T D G^T (nq_l x m)
      addBlock(J, L.q, cs.qRows, L.mu + row, cs.TDG, cs.column);
      // F_g = h - f: dh/dq = G T+
      cs.dFdq.noalias() = ev.G * cs.Til;
      addConstraintRows(J, c, L.lambda + row, L.q, qcols, cs.dFdq, cs.column);
    }
    addConstraintRows(J, c, L.mu + row, L.q, qcols, cs.vH, cs.column);
    addConstraintRows(J, c, L.mu + row, L.v, cols, ev.G, cs.column);
  }

  /// Index 1: the acceleration-level rows F_a = G a + v^T H_a w - f''.
  void index1Rows(int c, const ConstraintBlock& block) {
    const auto& [ci, con, cols, qcols, nl, nql, row, me, cs, ev] = block;
    // F_a = G a + v^T H_a w - f'', w = T v: d/dq = a^T H_a + d(v^T H_a w)/dq,
    // d/dv = v^T H_a T + (H_a w)^T (2 v^T H_a with T = I), d/da = G. The third-derivative
    // term d(v^T H_a w)/dq is the one block taken by central differences of the
    // analytic H_a (and of T) (docs/formulations.md).
    gather(cols, vp.data(), cs.al);
    if (identityT) {
      cs.wl = cs.vl;
    } else {
      gather(qcols, S.Tv.data(), cs.wl);
    }
    for (int a = 0; a < me; ++a) cs.dFdq.row(a).noalias() = cs.al.transpose() * ev.H[a];
    S.qPlus = q;
    S.qMinus = q;
    for (int k = 0; k < nql; ++k) {
      const int qc = qcols[k];
      const double h = 1e-6 * (1.0 + std::abs(q[qc]));
      S.qPlus[qc] = q[qc] + h;
      S.qMinus[qc] = q[qc] - h;
      con.evaluate(sys.constraintStates(ci, S.qPlus.data()), true, cs.plus);
      con.evaluate(sys.constraintStates(ci, S.qMinus.data()), true, cs.minus);
      if (!identityT) {  // (T v) at the perturbed coordinates, once per coordinate
        coordinateRates(sys, S.qPlus.data(), v.data(), S.TvPlus);
        gather(qcols, S.TvPlus.data(), cs.wl);
        coordinateRates(sys, S.qMinus.data(), v.data(), S.TvPlus);
        gather(qcols, S.TvPlus.data(), cs.wlMinus);
      }
      const VecX& wPlus = identityT ? cs.vl : cs.wl;
      const VecX& wMinus = identityT ? cs.vl : cs.wlMinus;
      for (int a = 0; a < me; ++a) {
        cs.Hv.noalias() = cs.plus.H[a] * wPlus;
        const double plus = cs.vl.dot(cs.Hv);
        cs.Hv.noalias() = cs.minus.H[a] * wMinus;
        cs.dFdq(a, k) += (plus - cs.vl.dot(cs.Hv)) / (2.0 * h);
      }
      S.qPlus[qc] = S.qMinus[qc] = q[qc];
    }
    addConstraintRows(J, c, L.lambda + row, L.q, qcols, cs.dFdq, cs.column);
    if (identityT) {
      cs.vH *= 2.0;
      cs.vH += cj * ev.G;
      addConstraintRows(J, c, L.lambda + row, L.v, cols, cs.vH, cs.column);
    } else {
      gather(qcols, S.Tv.data(), cs.wl);
      cs.dFdv.resize(me, nl);
      for (int a = 0; a < me; ++a) {
        cs.Hv.noalias() = ev.H[a] * cs.wl;
        cs.dFdv.row(a).noalias() = cs.vH.row(a) * cs.Tl;
        cs.dFdv.row(a) += cs.Hv.transpose();
      }
      cs.dFdv += cj * ev.G;
      addConstraintRows(J, c, L.lambda + row, L.v, cols, cs.dFdv, cs.column);
    }
  }

  /// The released equations' identity rows and, with T != I, the dT/dq term of F_q.
  void releasedAndRateRows() {
    // released equations: d(lambda_k)/d(lambda_k) = 1 (and d(mu_k)/d(mu_k) = 1)
    for (const int r : released_) {
      J.add(L.lambda + r, L.lambda + r, 1.0);
      if (L.mu >= 0) J.add(L.mu + r, L.mu + r, 1.0);
    }
    if (!identityT) {
      // F_q = q' + T(q) w, w = D G^T mu - v: the dT/dq term at fixed w
      S.w = S.DGtmu - v;
      for (int b = 0; b < sys.numBodies(); ++b) {
        const BodyIndex bi(b);
        const Body& body = sys.body(bi);
        const int nqb = body.numCoordinates(), qoff = sys.coordinateOffset(bi);
        if (nqb == 0 || body.velocitiesAreCoordinateRates()) continue;
        body.addCoordinateRateJacobian(q.segment(qoff, nqb), S.w.segment(sys.velocityOffset(bi), body.numVelocities()),
                                       MatrixSink(J, L.q + qoff, L.q + qoff));
      }
    }
  }

  /// J(row0 + i, colOffset + cols[j]) += B(i, j) over the kept rows i of constraint c.
  void addConstraintRows(JacobianSink& J, int c, int row0, int colOffset, const std::vector<int>& cols, const MatX& B,
                         VecX& buf) const {
    if (!partial_[c]) return addRowsBlock(J, row0, colOffset, cols, B);
    const std::vector<int>& kept = keptRows_[c];
    const int n = static_cast<int>(kept.size());
    for (size_t j = 0; j < cols.size(); ++j) {
      for (int i = 0; i < n; ++i) buf[i] = B(kept[i], static_cast<Eigen::Index>(j));
      J.addColumn(colOffset + cols[j], row0, kept.data(), buf.data(), n, 1.0);
    }
  }

  const System& sys;
  const DaeLayout& L;
  Formulation formulation_;
  const VecX& metric_;
  const std::vector<int>& released_;
  const std::vector<std::vector<int>>& keptRows_;
  const std::vector<char>& partial_;
  const std::vector<SparsePattern>& ratePattern_;
  const std::vector<SparsePattern>& rateInversePattern_;
  DaeSystemScratch& S;
  JacobianSink& J;
  double t;
  const double* y;
  double cj;
  ConstMap q, v, vp;
};

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
  VecX D = VecX::Ones(sys.numVelocities());
  const std::vector<CoordinateKind> kinds = sys.velocityKinds();
  for (int k = 0; k < D.size(); ++k) {
    if (kinds[k] == CoordinateKind::Elastic) D[k] = kElasticStabilisationWeight;
  }
  return D;
}

DaeSystem::DaeSystem(const System& sys, Formulation formulation)
    : DaeSystem(sys, formulation, defaultStabilisationMetric(sys)) {}

DaeSystem::DaeSystem(const System& sys, Formulation formulation, VecX stabilisationMetric)
    : DaeSystem(sys, formulation, std::move(stabilisationMetric), {}) {}

DaeSystem::DaeSystem(const System& sys, Formulation formulation, VecX stabilisationMetric, std::vector<int> released)
    : sys_(sys), formulation_(formulation), metric_(std::move(stabilisationMetric)), released_(std::move(released)) {
  if (!sys.isFinalized()) throw InputError("DaeSystem: the system must be finalized first");
  keptRows_.assign(sys.numConstraints(), {});
  partial_.assign(sys.numConstraints(), 0);
  for (size_t k = 0; k < released_.size(); ++k) {
    const int r = released_[k];
    if (r < 0 || r >= sys.numConstraintEquations() || (k > 0 && r <= released_[k - 1])) {
      throw InputError("DaeSystem: released constraint equations must be ascending indices below " +
                       std::to_string(sys.numConstraintEquations()) + ", got " + std::to_string(r));
    }
  }
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const int row = sys.constraintOffset(ci), me = sys.constraint(ci).numEquations();
    for (int a = 0; a < me; ++a) {
      if (std::binary_search(released_.begin(), released_.end(), row + a)) {
        partial_[c] = 1;
      } else {
        keptRows_[c].push_back(a);
      }
    }
  }
  if (metric_.size() != sys.numVelocities() || !(metric_.minCoeff() > 0.0) || !metric_.allFinite()) {
    throw InputError("DaeSystem: the stabilisation metric must have one positive entry per velocity");
  }
  DaeLayout& L = layout_;
  L.nq = sys.numCoordinates();
  L.nv = sys.numVelocities();
  L.m = sys.numConstraintEquations();
  L.q = 0;
  L.v = L.nq;
  L.lambda = L.nq + L.nv;
  L.mu = formulation == Formulation::Ggl ? L.nq + L.nv + L.m : -1;
  L.size = L.nq + L.nv + (formulation == Formulation::Ggl ? 2 : 1) * L.m;

  // T and T+ of the bodies with T != I, then the pattern of what the assembly writes,
  // recorded once at the initial state.
  const VecX q0 = sys.initialCoordinates();
  ratePattern_.resize(sys.numBodies());
  rateInversePattern_.resize(sys.numBodies());
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const Body& body = sys.body(bi);
    if (body.velocitiesAreCoordinateRates() || body.numCoordinates() == 0) continue;
    const auto qb = q0.segment(sys.coordinateOffset(bi), body.numCoordinates());
    const int n = std::max(body.numCoordinates(), body.numVelocities());
    ratePattern_[b] = recordPattern(n, [&](const MatrixSink& T) { body.addCoordinateRateMatrix(qb, T); });
    rateInversePattern_[b] = recordPattern(n, [&](const MatrixSink& T) { body.addCoordinateRateInverse(qb, T); });
  }
  std::vector<Eigen::Triplet<double>> written;
  JacobianSink recorder = JacobianSink::recorder(&written);
  VecX y, yp;
  packState(q0, VecX::Zero(L.nv), VecX::Zero(L.nv), VecX::Zero(L.m), y, yp);
  jacobian(0.0, y.data(), yp.data(), 1.0, recorder);
  std::vector<std::pair<int, int>> entries;
  entries.reserve(written.size());
  for (const auto& e : written) entries.emplace_back(e.row(), e.col());
  pattern_ = SparsePattern(L.size, std::move(entries));
}

VecX DaeSystem::differentialIds() const {
  VecX id = VecX::Zero(layout_.size);
  id.segment(layout_.q, layout_.nq).setOnes();
  if (formulation_ != Formulation::Index3) id.segment(layout_.v, layout_.nv).setOnes();
  return id;
}

std::vector<int64_t> DaeSystem::eliminationGroups() const {
  const DaeLayout& L = layout_;
  std::vector<int64_t> groups(L.size, 0);
  for (int k = L.lambda; k < L.size; ++k) groups[k] = 2;
  for (int f : sys_.frameCoordinates()) groups[L.q + f] = 1;
  for (int f : sys_.frameVelocities()) groups[L.v + f] = 1;
  return groups;
}

std::unique_ptr<DaeScratch> DaeSystem::makeScratch() const {
  const System& sys = sys_;
  const bool identityT = sys.velocitiesAreCoordinateRates();
  auto s = std::make_unique<DaeSystemScratch>();
  s->bodyForce.reserve(sys.numBodies());
  if (!identityT) {
    s->T.resize(sys.numBodies());
    s->Tinv.resize(sys.numBodies());
  }
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    s->bodyForce.emplace_back(sys.numVelocities(bi));
    if (!identityT && !sys.body(bi).velocitiesAreCoordinateRates()) {  // T and T+ only where T != I
      s->T[b].assign(ratePattern_[b].nonZeros(), 0.0);
      s->Tinv[b].assign(rateInversePattern_[b].nonZeros(), 0.0);
    }
  }
  s->constraints.resize(sys.numConstraints());
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const int nl = static_cast<int>(sys.constraintColumns(ci).size()), me = sys.constraint(ci).numEquations();
    const int nql = static_cast<int>(sys.constraintCoordinateColumns(ci).size());
    ConstraintScratch& cs = s->constraints[c];
    cs.vl.resize(nl);
    cs.al.resize(nl);
    cs.Hv.resize(nl);
    cs.f.setZero(me);
    cs.df.setZero(me);
    cs.ddf.setZero(me);
    cs.Hx.resize(nl, nql);
    cs.vH.resize(me, nql);
    cs.dFdq.resize(me, nql);
    cs.vRows = SortedIndex(sys.constraintColumns(ci));
    cs.qRows = SortedIndex(sys.constraintCoordinateColumns(ci));
    cs.column.resize(std::max({nl, nql, me}));
  }
  s->forces.resize(sys.numForces());
  for (int f = 0; f < sys.numForces(); ++f) {
    const int nl = static_cast<int>(sys.forceColumns(ForceIndex(f)).size());
    const int nql = static_cast<int>(sys.forceCoordinateColumns(ForceIndex(f)).size());
    ForceScratch& fs = s->forces[f];
    fs.vl.resize(nl);
    fs.Q.resize(nl);
    fs.dQdq.resize(nl, nql);
    fs.dQdv.resize(nl, nl);
    fs.vRows = SortedIndex(sys.forceColumns(ForceIndex(f)));
    fs.column.resize(nl);
  }
  s->qPlus.resize(sys.numCoordinates());
  s->qMinus.resize(sys.numCoordinates());
  if (!identityT) {
    s->DGtmu.resize(sys.numVelocities());
    s->w.resize(sys.numVelocities());
    s->Tv.resize(sys.numCoordinates());
    s->TvPlus.resize(sys.numCoordinates());
  }
  return s;
}

void DaeSystem::packState(const VecX& q, const VecX& v, const VecX& a, const VecX& lambda,
                          VecX& y, VecX& yp) const {
  const DaeLayout& L = layout_;
  y = VecX::Zero(L.size);
  yp = VecX::Zero(L.size);
  y.segment(L.q, L.nq) = q;
  y.segment(L.v, L.nv) = v;
  y.segment(L.lambda, L.m) = lambda;
  yp.segment(L.q, L.nq) = sys_.coordinateRates(q, v);
  yp.segment(L.v, L.nv) = a;
}

void DaeSystem::residual(double t, const double* y, const double* yp, double* F, DaeScratch& scratch) const {
  pollStop(t);  // a SIGINT does not wait for the next output (core/stop_request.hpp)
  if (sys_.velocitiesAreCoordinateRates()) {
    residualImpl<true>(t, y, yp, F, scratch, nullptr);
  } else {
    residualImpl<false>(t, y, yp, F, scratch, nullptr);
  }
}

void DaeSystem::residualOfParts(double t, const double* y, const double* yp, double* F, const ResidualParts& parts,
                                DaeScratch& scratch) const {
  if (parts.bodies.size() != static_cast<size_t>(sys_.numBodies()) ||
      parts.forces.size() != static_cast<size_t>(sys_.numForces()) ||
      parts.constraints.size() != static_cast<size_t>(sys_.numConstraints())) {
    throw std::logic_error("DaeSystem::residualOfParts: parts of another system");
  }
  if (sys_.velocitiesAreCoordinateRates()) {
    residualImpl<true>(t, y, yp, F, scratch, &parts);
  } else {
    residualImpl<false>(t, y, yp, F, scratch, &parts);
  }
}

ResidualParts ResidualParts::none(const System& sys) {
  return {std::vector<char>(static_cast<size_t>(sys.numBodies()), 0),
          std::vector<char>(static_cast<size_t>(sys.numForces()), 0),
          std::vector<char>(static_cast<size_t>(sys.numConstraints()), 0)};
}

void DaeSystem::jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                         DaeScratch& scratch) const {
  if (sys_.velocitiesAreCoordinateRates()) {
    jacobianImpl<true>(t, y, yp, cj, J, scratch);
  } else {
    jacobianImpl<false>(t, y, yp, cj, J, scratch);
  }
}

void DaeSystem::addRateJacobianProduct(double, const double* y, const double*, const double* x, double* r,
                                       DaeScratch&) const {
  if (formulation_ == Formulation::Index1) {
    throw std::logic_error("DaeSystem::addRateJacobianProduct: not provided for the index-1 form");
  }
  const DaeLayout& L = layout_;
  const System& sys = sys_;
  // dF_q/dq' = I and dF_v/dv' = M(q) of the GGL residual (class comment); nothing else holds y'
  Eigen::Map<VecX>(r + L.q, L.nq) += ConstMap(x + L.q, L.nq);
  const ConstMap q(y + L.q, L.nq), xv(x + L.v, L.nv);
  Eigen::Map<VecX> rv(r + L.v, L.nv);
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const int nqb = sys.numCoordinates(bi), nvb = sys.numVelocities(bi);
    if (nqb == 0) continue;
    const int voff = sys.velocityOffset(bi);
    sys.body(bi).addMassTimes(q.segment(sys.coordinateOffset(bi), nqb), xv.segment(voff, nvb), rv.segment(voff, nvb));
  }
}

template <bool IdentityT>
void DaeSystem::residualImpl(double t, const double* y, const double* yp, double* F, DaeScratch& scratch,
                             const ResidualParts* parts) const {
  const DaeLayout& L = layout_;
  const System& sys = sys_;
  DaeSystemScratch& S = scratchOf(scratch);
  constexpr bool identityT = IdentityT;
  ConstMap q(y + L.q, L.nq), v(y + L.v, L.nv), qp(yp + L.q, L.nq), vp(yp + L.v, L.nv);
  Eigen::Map<VecX> Fq(F + L.q, L.nq), Fv(F + L.v, L.nv);
  // F_q = q' - T (v - D G^T mu) (GearGuptaLeimkuhler1985): with T = I written at once,
  // otherwise after the constraints have accumulated D G^T mu.
  if (identityT) {
    Fq = qp - v;
  } else {
    Fq = qp;
    S.DGtmu.setZero();
  }
  Fv.setZero();
  // without gravity its terms are zero: not evaluated (a rotation and a pass per body)
  const bool withGravity = sys.gravity() != Vec3::Zero();
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi(b);
    const int nqb = sys.numCoordinates(bi), nvb = sys.numVelocities(bi);
    if (nqb == 0 || (parts && !parts->bodies[b])) continue;
    const Body& body = sys.body(bi);
    const int voff = sys.velocityOffset(bi);
    const auto qb = q.segment(sys.coordinateOffset(bi), nqb);
    VecX& Qb = S.bodyForce[b];
    Qb.setZero();
    body.addInternalForces(qb, v.segment(voff, nvb), Qb);
    if (withGravity) body.addGravityForce(qb, sys.gravity(), Qb);
    Fv.segment(voff, nvb) -= Qb;
    body.addMassTimes(qb, vp.segment(voff, nvb), Fv.segment(voff, nvb));
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    if (parts && !parts->forces[f]) continue;
    const ForceIndex fi(f);
    const auto& cols = sys.forceColumns(fi);
    ForceScratch& fs = S.forces[f];
    gather(cols, v.data(), fs.vl);
    fs.Q.setZero();
    sys.force(fi).addForce(t, sys.forceStates(fi, q.data()), fs.vl, fs.Q, nullptr, nullptr, fs.work);
    for (size_t k = 0; k < cols.size(); ++k) Fv[cols[k]] -= fs.Q[k];
  }
  const bool needH = formulation_ == Formulation::Index1;
  if (needH && !identityT) coordinateRates(sys, q.data(), v.data(), S.Tv);
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const Constraint& con = sys.constraint(ci);
    const auto& cols = sys.constraintColumns(ci);
    const int row = sys.constraintOffset(ci), me = con.numEquations(), nl = static_cast<int>(cols.size());
    if (parts && !parts->constraints[c]) {  // left out: its rows zero, nothing into F_q and F_v
      std::fill(F + L.lambda + row, F + L.lambda + row + me, 0.0);
      if (L.mu >= 0) std::fill(F + L.mu + row, F + L.mu + row + me, 0.0);
      continue;
    }
    ConstraintScratch& cs = S.constraints[c];
    const ConstraintEvaluation& ev = cs.ev;
    con.evaluate(sys.constraintStates(ci, q.data()), needH, cs.ev);
    // joints prescribe nothing: their f, f', f'' stay the zeros makeScratch set
    if (sys.constraintIsDriver(ci)) con.timeFunction(t, cs.f, cs.df, cs.ddf);
    // F_v += G^T lambda (G is m_c x n_c, a few entries: plain loops beat Eigen's GEMV;
    // GGL takes it in its one pass over G below)
    const double* lambda = y + L.lambda + row;
    if (formulation_ != Formulation::Ggl) {
      for (int k = 0; k < nl; ++k) Fv[cols[k]] += columnDot(ev.G, k, lambda);
    }
    Eigen::Map<VecX> Fc(F + L.lambda + row, me);
    switch (formulation_) {
      case Formulation::Ggl: {
        // F_v += G^T lambda;  F_q += T D G^T mu;  F_g = h - f;  F_gv = G v - f': one pass
        // over the columns of G (GearGuptaLeimkuhler1985)
        const double* mu = y + L.mu + row;
        if (const double period = sys.constraintPeriod(ci); period > 0.0) {
          for (int a = 0; a < me; ++a) cs.f[a] = ev.h[a] - std::remainder(ev.h[a] - cs.f[a], period);
        }
        Fc = ev.h - cs.f;
        double* Fcv = F + L.mu + row;
        for (int a = 0; a < me; ++a) Fcv[a] = -cs.df[a];
        double* DGtmu = identityT ? Fq.data() : S.DGtmu.data();  // F_q at once with T = I
        const GglColumns pass{ev.G.data(), cols.data(), nl, lambda, mu, v.data(), metric_.data(), Fv.data(), DGtmu,
                              Fcv};
        switch (me) {  // the usual sizes unrolled
          case 1: pass.run<1>(me); break;
          case 2: pass.run<2>(me); break;
          case 3: pass.run<3>(me); break;
          default: pass.run<0>(me); break;
        }
        break;
      }
      case Formulation::Index3:
        if (const double period = sys.constraintPeriod(ci); period > 0.0) {
          for (int a = 0; a < me; ++a) cs.f[a] = ev.h[a] - std::remainder(ev.h[a] - cs.f[a], period);
        }
        Fc = ev.h - cs.f;
        break;
      case Formulation::Index1: {
        // F_a = G a + v^T H_a T v - f'' (the acceleration equation, Haug1989)
        gather(cols, v.data(), cs.vl);
        gather(cols, vp.data(), cs.al);
        if (identityT) {
          cs.wl = cs.vl;
        } else {
          gather(sys.constraintCoordinateColumns(ci), S.Tv.data(), cs.wl);
        }
        for (int a = 0; a < me; ++a) {
          cs.Hv.noalias() = ev.H[a] * cs.wl;
          Fc[a] = ev.G.row(a).dot(cs.al) + cs.vl.dot(cs.Hv) - cs.ddf[a];
        }
        break;
      }
    }
  }
  // released equations: lambda_k = 0 (and mu_k = 0) in place of their constraint rows
  for (const int r : released_) {
    F[L.lambda + r] = y[L.lambda + r];
    if (L.mu >= 0) F[L.mu + r] = y[L.mu + r];
  }
  if (!identityT) {
    S.w = S.DGtmu - v;  // F_q = q' + T (D G^T mu - v) (GearGuptaLeimkuhler1985)
    for (int b = 0; b < sys.numBodies(); ++b) {
      const BodyIndex bi(b);
      const Body& body = sys.body(bi);
      const int nqb = body.numCoordinates(), qoff = sys.coordinateOffset(bi);
      if (nqb == 0) continue;
      body.addCoordinateRate(q.segment(qoff, nqb), S.w.segment(sys.velocityOffset(bi), body.numVelocities()),
                             Fq.segment(qoff, nqb));
    }
  }
}

template <bool IdentityT>
void DaeSystem::jacobianImpl(double t, const double* y, const double* yp, double cj, JacobianSink& sink,
                             DaeScratch& scratch) const {
  DaeSystemScratch& S = scratchOf(scratch);
  // into the DAE's own pattern, the entries' positions as the last assembly found them
  JacobianSink positioned = sink.pattern() == &pattern_ ? sink.withPositions(S.positions) : sink;
  const typename JacobianAssembly<IdentityT>::Model model{
      sys_, layout_, formulation_, metric_, released_, keptRows_, partial_, ratePattern_, rateInversePattern_};
  JacobianAssembly<IdentityT>(model, S, positioned, t, y, yp, cj).run();
}

}  // namespace flexmbd
