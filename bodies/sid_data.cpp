#include "bodies/sid_data.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

namespace {

using Mat3Grid = std::array<std::array<MatX, 3>, 3>;

/// The inertia tensor of a second moment: int rho u~^T u~ dV = tr(J) 1 - J (Shabana2005, eq. 5.110).
Mat3 inertiaOf(const Mat3& secondMoment) { return secondMoment.trace() * Mat3::Identity() - secondMoment; }
/// Its inverse: J = tr(I) / 2 1 - I (inverting Shabana2005, eq. 5.110).
Mat3 secondMomentOf(const Mat3& inertia) { return 0.5 * inertia.trace() * Mat3::Identity() - inertia; }

/// P_j(k, l) = int rho u0_k N_lj dV = positionShape[k](l, j).
Mat3 positionMoment(const FfrInvariants3d& inv, int j) {
  Mat3 P;
  for (int k = 0; k < 3; ++k) P.row(k) = inv.positionShape[k].col(j).transpose();
  return P;
}

/// int rho u0 x N_j dV from P_j: (u0 x N)_x = u0_y N_z - u0_z N_y.
Vec3 crossMoment(const Mat3& P) { return {P(1, 2) - P(2, 1), P(2, 0) - P(0, 2), P(0, 1) - P(1, 0)}; }

Mat3Grid denseShapeIntegrals(const std::array<std::array<SpMat, 3>, 3>& s) {
  Mat3Grid d;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) d[a][b] = s[a][b].size() ? MatX(s[a][b]) : MatX();
  return d;
}

/// W_i(k, j) with int rho (N_k x N_j) dV = (W_x, W_y, W_z)(k, j): W_x = S_yz - S_zy, ...
std::array<MatX, 3> crossShapeIntegrals(const Mat3Grid& S) {
  return {S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0]};
}

/// The axes (a, b) of Oe's column c: w-bar_c = w_a w_b.
constexpr std::array<std::pair<int, int>, 6> kOeColumn = {{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}}};

/// The row of Oe for a change E = dJ/dq_j of the second moment: the centrifugal force
/// Q_j = 1/2 w^T (dI/dq_j) w (Lagrange, T = 1/2 w^T I(q) w) with Oe w-bar = -Q_j, w-bar =
/// (w_x^2, w_y^2, w_z^2, w_x w_y, w_y w_z, w_x w_z) (the SID's Oe: Wallrapp1994).
Eigen::Matrix<double, 1, 6> centrifugalRow(const Mat3& E) {
  const double tr = E.trace();
  Eigen::Matrix<double, 1, 6> r;
  r << -0.5 * (tr - E(0, 0)), -0.5 * (tr - E(1, 1)), -0.5 * (tr - E(2, 2)), E(0, 1), E(1, 2), E(0, 2);
  return r;
}

/// C_kl(a, b): the quadratic part of J, J_ab = ... + q^T C_ab q with C_ab = sym(S_ab) + R_ab.
Mat3 quadraticSecondMoment(const Mat3Grid& S, const FfrInvariants3d& inv, int k, int l) {
  Mat3 C;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      C(a, b) = 0.5 * (S[a][b](k, l) + S[a][b](l, k));
      if (inv.rKL[a][b].size()) C(a, b) += inv.rKL[a][b].coeff(k, l);
    }
  }
  return C;
}

bool hasSectionRotationMoment(const FfrInvariants3d& inv) {
  for (const auto& row : inv.rKL)
    for (const SpMat& R : row)
      if (R.nonZeros()) return true;
  return false;
}

SidNode nodeOf(const FfrPoint3d& p, int index, int n) {
  SidNode nd;
  nd.name = std::to_string(index + 1);
  nd.rframe = "body ref";
  nd.origin = SidTaylor::zero("origin", 1, 3, 1, n, SidTaylor::Full);
  nd.origin.m0 = p.position;
  nd.phi = SidTaylor::zero("phi", 0, 3, n, 0, SidTaylor::Full);
  nd.phi.m0 = p.shape;
  nd.psi = SidTaylor::zero("psi", 0, 3, n, 0, SidTaylor::Full);
  nd.psi.m0 = p.rotationShape;
  nd.ap = SidTaylor::zero("AP", 1, 3, 3, n, SidTaylor::Full);
  nd.ap.m0 = Mat3::Identity();
  for (int k = 0; k < n; ++k) {
    nd.origin.m1[k] = p.shape.col(k);
    nd.ap.m1[k] = skew(p.rotationShape.col(k));  // the node frame I + skew(N_theta q)
  }
  return nd;
}

// ----- reading: the primary blocks ------------------------------------------------

[[noreturn]] void fail(const std::string& owner, const std::string& what) {
  throw InputError(owner + ": SID " + what);
}

/// A block's shape and order (`minOrder`: the first-order term is needed); `block` names it
/// when it is missing.
void requireShape(const SidTaylor& t, const char* block, int nrow, int ncol, int n, int minOrder,
                  const std::string& owner) {
  if (t.name.empty()) fail(owner, std::string("has no block ") + block + " (required; docs/fe-import.md, \"SID\")");
  if (t.nrow != nrow || t.ncol != ncol) {
    fail(owner, "block " + t.name + " is " + std::to_string(t.nrow) + " x " + std::to_string(t.ncol) + "; expected " +
                    std::to_string(nrow) + " x " + std::to_string(ncol) + " (nelastq = " + std::to_string(n) + ")");
  }
  if (t.order < minOrder) {
    fail(owner, "block " + t.name + " has order " + std::to_string(t.order) + "; flexmbd needs its first-order term" +
                    (t.name == "Gr" ? " (the S_kl integrals of the quadratic inertia terms)" : ""));
  }
  if (t.order >= 1 && t.nq != n) {
    fail(owner, "block " + t.name + " has nq = " + std::to_string(t.nq) + "; expected nelastq = " + std::to_string(n));
  }
}

/// The first-order term k of `t`, or zero when the file gives `t` to order 0.
MatX firstOrder(const SidTaylor& t, int k) { return t.order >= 1 ? t.m1[k] : MatX::Zero(t.nrow, t.ncol); }

SpMat sparse(const MatX& A) { return A.sparseView(0.0, 0.0); }

/// H_i (nf x nf) = Cr's first-order term less the W_i of the S_kl: Cr.M1_k(j, i) =
/// W_i(k, j) + H_i(k, j). Zero (absent) when within kSidConsistency of Cr.M1's size.
void readSectionRotationCoupling(const SidData& sid, const std::array<MatX, 3>& W, FfrInvariants3d& inv) {
  const int n = sid.numElastic();
  if (sid.Cr.order < 1) return;
  std::array<MatX, 3> H;
  double scale = 0.0, largest = 0.0;
  for (int i = 0; i < 3; ++i) {
    H[i].resize(n, n);
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        H[i](k, j) = sid.Cr.m1[k](j, i) - W[i](k, j);
        scale = std::max(scale, std::abs(sid.Cr.m1[k](j, i)));
        largest = std::max(largest, std::abs(H[i](k, j)));
      }
    }
  }
  if (largest <= kSidConsistency * scale) return;
  for (int i = 0; i < 3; ++i) inv.hI[i] = sparse(0.5 * (H[i] + H[i].transpose()));
}

/// R_ab (k, l) = C_kl(a, b) - sym(S_ab)(k, l), C_kl from J's second-order term.
void readSectionRotationMoment(const SidData& sid, const Mat3Grid& S, FfrInvariants3d& inv,
                               const std::string& owner) {
  const int n = sid.numElastic();
  if (sid.J.order < 2) return;
  if (sid.J.nqn != n) {
    fail(owner, "block J has nqn = " + std::to_string(sid.J.nqn) + "; expected nelastq = " + std::to_string(n));
  }
  Mat3Grid R;
  double scale = 0.0, largest = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) R[a][b] = MatX::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    for (int l = 0; l < n; ++l) {
      const Mat3 C = secondMomentOf(sid.J.m2[k + n * l]);
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          R[a][b](k, l) = C(a, b) - 0.5 * (S[a][b](k, l) + S[a][b](l, k));
          scale = std::max(scale, std::abs(C(a, b)));
          largest = std::max(largest, std::abs(R[a][b](k, l)));
        }
      }
    }
  }
  if (largest <= kSidConsistency * scale) return;
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) {
      const MatX Rab = 0.5 * (R[a][b] + R[b][a]);
      inv.rKL[a][b] = sparse(0.5 * (Rab + Rab.transpose()));
      inv.rKL[b][a] = inv.rKL[a][b];
    }
  }
}

/// G_ab from Oe's first-order term beyond the inertia (the spin softening and the
/// centrifugal terms of the S_kl, R_kl): Oe.M1_k(j, c) - inertia = (1 or 2) G_ab(j, k).
/// None when within kSidConsistency of Oe.M1's size.
void readSpinStiffness(const SidData& sid, FfrInvariants3d& inv, const std::string& owner) {
  if (sid.Oe.name.empty() || sid.Oe.order < 1) return;
  const int n = sid.numElastic();
  const SidTaylor inertia = sidFromInvariants(inv, sid.modeNames).Oe;
  std::array<std::array<MatX, 3>, 3> G;
  double scale = 0.0, largest = 0.0;
  for (int c = 0; c < 6; ++c) {
    const auto [a, b] = kOeColumn[c];
    G[a][b] = MatX::Zero(n, n);
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        const double e = sid.Oe.m1[k](j, c) - inertia.m1[k](j, c);
        G[a][b](j, k) = e / (a == b ? 1.0 : 2.0);
        scale = std::max(scale, std::abs(sid.Oe.m1[k](j, c)));
        largest = std::max(largest, std::abs(e));
      }
    }
  }
  if (largest <= kSidConsistency * scale) return;
  for (int c = 0; c < 6; ++c) {
    const auto [a, b] = kOeColumn[c];
    const double asym = (G[a][b] - G[a][b].transpose()).cwiseAbs().maxCoeff();
    if (asym > kSidConsistency * scale) {
      std::ostringstream os;
      os << "block Oe: its first-order terms beyond the inertia (the geometric stiffness per w-bar_" << c + 1
         << ") are not symmetric in the elastic coordinates (by " << asym << "); expected a stiffness matrix";
      fail(owner, os.str());
    }
    inv.spinStiffness[a][b] = sparse(0.5 * (G[a][b] + G[a][b].transpose()));
    inv.spinStiffness[b][a] = inv.spinStiffness[a][b];
  }
}

// ----- reading: the redundant blocks ---------------------------------------------

/// Entry (i, j) of term `t` ("m0(i, j)", "m1(i, j, k)"; 1-based as in the file).
std::string entryName(const std::string& term, int i, int j, int k) {
  std::ostringstream os;
  os << term << "(" << i + 1 << ", " << j + 1;
  if (k >= 0) os << ", " << k + 1;
  os << ")";
  return os.str();
}

/// `got` (the file's term) equals `want` (from the primary blocks) to kSidConsistency
/// of `scale`. `hint` ends the message.
void requireEqualTerm(const MatX& got, const MatX& want, double scale, const std::string& owner,
                      const std::string& block, const std::string& term, int k, const std::string& hint) {
  for (int i = 0; i < got.rows(); ++i) {
    for (int j = 0; j < got.cols(); ++j) {
      const double d = std::abs(got(i, j) - want(i, j));
      if (!(d <= kSidConsistency * scale)) {
        std::ostringstream os;
        os.precision(10);
        os << "block " << block << ", " << entryName(term, i, j, k) << " = " << got(i, j) << " differs from "
           << want(i, j) << ", the value the other blocks give (by " << d << "; allowed " << kSidConsistency
           << " of " << scale << ")" << hint;
        fail(owner, os.str());
      }
    }
  }
}

/// The file's block `got` against `want` regenerated from the invariants: the terms the
/// file has (a term it omits is its approximation); a term `want` lacks must be zero.
void requireEqualBlock(const SidTaylor& got, const SidTaylor& want, double scale0, double scale1,
                       const std::string& owner, const std::string& block, const std::string& hint) {
  if (got.name.empty()) return;  // an optional block the file does not give
  requireEqualTerm(got.m0, want.m0, scale0, owner, block, "m0", -1, hint);
  for (int k = 0; k < static_cast<int>(got.m1.size()); ++k) {
    const MatX w = k < static_cast<int>(want.m1.size()) ? want.m1[k] : MatX::Zero(got.nrow, got.ncol);
    requireEqualTerm(got.m1[k], w, scale1, owner, block, "m1", k, hint);
  }
}

double maxAbsOf(const MatX& A) { return A.size() ? A.cwiseAbs().maxCoeff() : 0.0; }

/// The blocks that the invariants determine (Ct, Gr's zeroth order, Ge, Oe, the nodes'
/// origin M1 and AP) compared with the file's; ksigma must be zero.
void checkRedundantBlocks(const SidData& sid, const FfrInvariants3d& inv, const std::string& owner) {
  const SidData want = sidFromInvariants(inv, sid.modeNames);
  const double sM = maxAbsOf(MatX(inv.mff)) + 1e-300;
  const double sS = std::sqrt(inv.mass * sM);                 // |S-bar_j| <= sqrt(m m_jj) (Cauchy-Schwarz)
  const double sP = std::sqrt(inv.secondMoment.trace() * sM);  // |P_j| <= sqrt(tr J m_jj)
  const std::string stiffening = "; first-order terms beyond the inertia are geometric stiffening, which flexmbd "
                                 "does not read (docs/fe-import.md, \"SID\")";
  requireEqualBlock(sid.Ct, want.Ct, sS, sM, owner, "Ct", stiffening);
  SidTaylor gr0 = sid.Gr;  // Gr's first-order term gave the S_kl
  gr0.m1.clear();
  requireEqualBlock(gr0, want.Gr, sP, sM, owner, "Gr", "");
  requireEqualBlock(sid.Ge, want.Ge, sM, sM, owner, "Ge", "");
  requireEqualBlock(sid.Oe, want.Oe, sP, sM, owner, "Oe", "");
  if (!sid.ksigma.name.empty()) {
    requireEqualBlock(sid.ksigma, SidTaylor::zero("ksigma", 0, sid.ksigma.nrow, 1, 0, SidTaylor::Zero), sM, sM,
                      owner, "ksigma",
                      "; reference stresses (ksigma) are not supported: expected none (docs/fe-import.md, \"SID\")");
  }
  double sPhi = 1e-300, sPsi = 1e-300;
  for (const FfrPoint3d& p : inv.points) {
    sPhi = std::max(sPhi, maxAbsOf(p.shape));
    sPsi = std::max(sPsi, maxAbsOf(p.rotationShape));
  }
  for (std::size_t i = 0; i < sid.nodes.size(); ++i) {
    const std::string where = "node " + sid.nodes[i].name + " ";
    SidTaylor origin = sid.nodes[i].origin;
    origin.m0 = want.nodes[i].origin.m0;  // the primary position
    requireEqualBlock(origin, want.nodes[i].origin, sPhi, sPhi, owner, where + "origin", "");
    SidTaylor phi = sid.nodes[i].phi;  // phi's first-order term would be stiffening
    phi.m0 = want.nodes[i].phi.m0;
    requireEqualBlock(phi, want.nodes[i].phi, sPhi, sPhi, owner, where + "phi", stiffening);
    requireEqualBlock(sid.nodes[i].ap, want.nodes[i].ap, 1.0, sPsi, owner, where + "AP", "");
  }
}

}  // namespace

SidTaylor SidTaylor::zero(std::string name, int order, int nrow, int ncol, int nq, int structure) {
  SidTaylor t;
  t.name = std::move(name);
  t.order = order;
  t.nrow = nrow;
  t.ncol = ncol;
  t.nq = order >= 1 ? nq : 0;
  t.nqn = order >= 2 ? nq : 0;
  t.structure = structure;
  t.m0 = MatX::Zero(nrow, ncol);
  if (order >= 1) t.m1.assign(nq, MatX::Zero(nrow, ncol));
  if (order >= 2) t.m2.assign(static_cast<std::size_t>(nq) * nq, MatX::Zero(nrow, ncol));
  return t;
}

std::vector<const SidTaylor*> SidData::blocks() const {
  return {&mdCM, &J, &Ct, &Cr, &Me, &Gr, &Ge, &Oe, &ksigma, &Ke, &De};
}
std::vector<SidTaylor*> SidData::blocks() { return {&mdCM, &J, &Ct, &Cr, &Me, &Gr, &Ge, &Oe, &ksigma, &Ke, &De}; }

SidData sidFromInvariants(const FfrInvariants3d& inv, std::vector<std::string> modeNames) {
  const int n = inv.numElastic();
  if (modeNames.empty()) {
    for (int k = 0; k < n; ++k) modeNames.push_back("q" + std::to_string(k + 1));
  }
  if (static_cast<int>(modeNames.size()) != n) {
    throw InputError("SID: " + std::to_string(modeNames.size()) + " mode names for " + std::to_string(n) +
                     " elastic coordinates");
  }
  const MatX mff(inv.mff);
  const Mat3Grid S = denseShapeIntegrals(inv.sKL);
  const std::array<MatX, 3> W = crossShapeIntegrals(S);
  std::vector<Mat3> P(n);
  for (int j = 0; j < n; ++j) P[j] = positionMoment(inv, j);

  SidData s;
  s.mass = inv.mass;
  s.modeNames = std::move(modeNames);
  for (std::size_t i = 0; i < inv.points.size(); ++i) s.nodes.push_back(nodeOf(inv.points[i], static_cast<int>(i), n));

  s.mdCM = SidTaylor::zero("mdCM", 1, 3, 1, n, SidTaylor::Full);  // int rho (u0 + N q) dV
  s.mdCM.m0 = inv.firstMoment;
  const bool secondOrderJ = hasSectionRotationMoment(inv);
  s.J = SidTaylor::zero("J", secondOrderJ ? 2 : 1, 3, 3, n, SidTaylor::Symmetric);
  s.J.m0 = inertiaOf(inv.secondMoment);
  s.Ct = SidTaylor::zero("Ct", 0, n, 3, 0, SidTaylor::Full);
  s.Ct.m0 = inv.sBar.transpose();
  s.Cr = SidTaylor::zero("Cr", 1, n, 3, n, SidTaylor::Full);
  s.Me = SidTaylor::zero("Me", 0, n, n, 0, SidTaylor::Symmetric);
  s.Me.m0 = mff;
  s.Gr = SidTaylor::zero("Gr", 1, 3, 3 * n, n, SidTaylor::Full);
  s.Ge = SidTaylor::zero("Ge", 0, n, 3 * n, 0, SidTaylor::Full);
  s.Oe = SidTaylor::zero("Oe", 1, n, 6, n, SidTaylor::Full);
  s.ksigma = SidTaylor::zero("ksigma", 0, n, 1, 0, SidTaylor::Zero);
  s.Ke = SidTaylor::zero("Ke", 0, n, n, 0, SidTaylor::Symmetric);
  s.Ke.m0 = MatX(inv.kff);
  s.De = SidTaylor::zero("De", 0, n, n, 0, SidTaylor::Symmetric);
  if (inv.dff.size()) s.De.m0 = MatX(inv.dff);

  for (int j = 0; j < n; ++j) {
    s.mdCM.m1[j] = inv.sBar.col(j);
    s.J.m1[j] = inertiaOf(P[j] + P[j].transpose());             // dJ/dq_j = P_j + P_j^T
    s.Cr.m0.row(j) = crossMoment(P[j]).transpose();             // int rho u0 x N_j dV
    s.Gr.m0.block<3, 3>(0, 3 * j) = -2.0 * (P[j].transpose() - P[j].trace() * Mat3::Identity());  // -2 int u0~ N_j~
    s.Oe.m0.row(j) = centrifugalRow(P[j] + P[j].transpose());
  }
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      Mat3 G, C2;  // G = int N_k~ N_j~ = S(j, k) - m_ff(j, k) 1; 2 C_jk = d^2 J / dq_j dq_k
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) G(a, b) = S[a][b](j, k) - (a == b ? mff(j, k) : 0.0);
      s.Gr.m1[k].block<3, 3>(0, 3 * j) = -2.0 * G;
      C2 = 2.0 * quadraticSecondMoment(S, inv, j, k);
      s.Oe.m1[k].row(j) = centrifugalRow(C2);
      for (int c = 0; c < 6; ++c) {  // spin stiffening: Q_j -= sum_ab w_a w_b G_ab(j, k) q_k
        const auto [a, b] = kOeColumn[c];
        const SpMat& G = inv.spinStiffness[a][b];
        if (G.size()) s.Oe.m1[k](j, c) += (a == b ? 1.0 : 2.0) * G.coeff(j, k);
      }
      for (int i = 0; i < 3; ++i) {
        s.Cr.m1[k](j, i) = W[i](k, j) + (inv.hI[i].size() ? inv.hI[i].coeff(k, j) : 0.0);  // int N_k~ N_j + H
        s.Ge.m0(k, 3 * j + i) = 2.0 * W[i](k, j);                                          // 2 int N^T N_j~
      }
      if (secondOrderJ) s.J.m2[j + n * k] = inertiaOf(quadraticSecondMoment(S, inv, j, k));
    }
  }
  return s;
}

FfrInvariants3d invariantsFromSid(const SidData& sid, const std::string& owner) {
  const int n = sid.numElastic();
  requireShape(sid.mdCM, "mdCM", 3, 1, n, 0, owner);
  requireShape(sid.J, "J", 3, 3, n, 0, owner);
  requireShape(sid.Cr, "Cr", n, 3, n, 0, owner);
  requireShape(sid.Me, "Me", n, n, n, 0, owner);
  requireShape(sid.Gr, "Gr", 3, 3 * n, n, 1, owner);
  requireShape(sid.Ke, "Ke", n, n, n, 0, owner);
  if (!sid.De.name.empty()) requireShape(sid.De, "De", n, n, n, 0, owner);
  if (!sid.Ct.name.empty()) requireShape(sid.Ct, "Ct", n, 3, n, 0, owner);
  if (!sid.Ge.name.empty()) requireShape(sid.Ge, "Ge", n, 3 * n, n, 0, owner);
  if (!sid.Oe.name.empty()) requireShape(sid.Oe, "Oe", n, 6, n, 0, owner);
  if (!sid.ksigma.name.empty()) requireShape(sid.ksigma, "ksigma", n, 1, n, 0, owner);
  for (const SidNode& nd : sid.nodes) {
    requireShape(nd.origin, "origin", 3, 1, n, 0, owner + ", node " + nd.name);
    requireShape(nd.phi, "phi", 3, n, n, 0, owner + ", node " + nd.name);
    requireShape(nd.psi, "psi", 3, n, n, 0, owner + ", node " + nd.name);
    if (!nd.ap.name.empty()) requireShape(nd.ap, "AP", 3, 3, n, 0, owner + ", node " + nd.name);
  }

  FfrInvariants3d inv;
  inv.mass = sid.mass;
  inv.firstMoment = sid.mdCM.m0.col(0);
  inv.sBar.resize(3, n);
  inv.secondMoment = secondMomentOf(sid.J.m0);
  for (int k = 0; k < 3; ++k) inv.positionShape[k].resize(3, n);
  for (int j = 0; j < n; ++j) {
    inv.sBar.col(j) = firstOrder(sid.mdCM, j);
    const Mat3 D = secondMomentOf(firstOrder(sid.J, j));          // P_j + P_j^T
    const Mat3 P = 0.5 * (D - skew(sid.Cr.m0.row(j).transpose()));  // P_j - P_j^T = -skew(int u0 x N_j)
    for (int k = 0; k < 3; ++k) inv.positionShape[k].col(j) = P.row(k).transpose();
  }
  const MatX mff = sid.Me.m0;
  inv.mff = sparse(mff);
  inv.kff = sparse(sid.Ke.m0);
  inv.dff = sid.De.name.empty() ? SpMat(n, n) : sparse(sid.De.m0);
  Mat3Grid S;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      S[a][b].resize(n, n);
      for (int k = 0; k < n; ++k)  // Gr.M1_k block j = -2 (S(j, k) - m_ff(j, k) 1)
        for (int j = 0; j < n; ++j) S[a][b](j, k) = -0.5 * sid.Gr.m1[k](a, 3 * j + b) + (a == b ? mff(j, k) : 0.0);
      inv.sKL[a][b] = sparse(S[a][b]);
    }
  }
  readSectionRotationCoupling(sid, crossShapeIntegrals(S), inv);
  readSectionRotationMoment(sid, S, inv, owner);
  readSpinStiffness(sid, inv, owner);
  for (const SidNode& nd : sid.nodes) {
    FfrPoint3d p;
    p.position = nd.origin.m0.col(0);
    p.shape = nd.phi.m0;
    p.rotationShape = nd.psi.m0;
    inv.points.push_back(p);
  }
  inv.validate(owner);
  checkRedundantBlocks(sid, inv, owner);
  return inv;
}

}  // namespace flexmbd
