#include "bodies/modal_reduction.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
// GCC 12 warns -Wuse-after-free inside Spectra (Eigen temporaries freed and reallocated
// by resize): a false positive of its inlining analysis (as analysis/linearization.cpp).
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <Spectra/MatOp/SparseCholesky.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsSolver.h>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/errors.hpp"
#include "core/linear_algebra.hpp"

namespace flexmbd {

std::vector<int> chosenModes(int count, const std::vector<int>& set, const std::string& owner) {
  if (count < 0) {
    throw InputError(owner + ": modes must be >= 0 (0 keeps the nodal coordinates), got " + std::to_string(count));
  }
  std::vector<int> keep = set;
  if (keep.empty()) {
    for (int k = 1; k <= count; ++k) keep.push_back(k);
  }
  std::vector<int> sorted = keep;
  std::sort(sorted.begin(), sorted.end());
  if (!sorted.empty() && sorted.front() < 1) {
    throw InputError(owner + ": mode " + std::to_string(sorted.front()) + " does not exist (modes are numbered from 1)");
  }
  const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
  if (twice != sorted.end()) {
    throw InputError(owner + ": mode " + std::to_string(*twice) + " is chosen twice; expected distinct modes");
  }
  return keep;
}

void fixModeSigns(MatX& phi) {
  constexpr double kTie = 1e-6;  // entries this close to the largest count as tied with it
  for (Eigen::Index k = 0; k < phi.cols(); ++k) {
    const double largest = phi.col(k).cwiseAbs().maxCoeff();
    Eigen::Index i = 0;
    while (i + 1 < phi.rows() && std::abs(phi(i, k)) < (1.0 - kTie) * largest) ++i;
    if (phi(i, k) < 0.0) phi.col(k) = -phi.col(k);
  }
}

MatX normalModes(const MatX& K, const MatX& M, const std::vector<int>& keep, const std::string& owner, VecX* omega,
                 const std::string& what) {
  const int available = static_cast<int>(K.rows());
  const int highest = keep.empty() ? 0 : *std::max_element(keep.begin(), keep.end());  // named if missing
  if (highest > available) {
    throw InputError(owner + ": " + what + " " + std::to_string(highest) + " does not exist (the mesh has " + what +
                     "s 1.." + std::to_string(available) + ")");
  }
  MatX Phi(K.rows(), keep.size());
  if (omega) omega->resize(static_cast<Eigen::Index>(keep.size()));
  if (keep.empty()) return Phi;
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(K, M);  // eigenvectors mass-normalised
  for (size_t k = 0; k < keep.size(); ++k) {
    Phi.col(k) = eig.eigenvectors().col(keep[k] - 1);
    if (omega) (*omega)[k] = std::sqrt(std::max(eig.eigenvalues()[keep[k] - 1], 0.0));
  }
  fixModeSigns(Phi);
  return Phi;
}

namespace {

/// The `nev` largest eigenvalues nu (descending) and their eigenvectors of A x = nu C x,
/// A symmetric, C symmetric positive definite: Lanczos in the C-inner product (Spectra's
/// SymGEigsSolver, Cholesky mode, on the sparse Cholesky factor of C; A only multiplied).
/// @throws InputError naming `owner`: C not positive definite (`notDefinite` says why
/// and what was expected), the solver not converging (`solver` names it).
void largestOfPencil(const SpMat& A, const SpMat& C, int nev, const std::string& owner, const std::string& notDefinite,
                     const std::string& solver, VecX& nu, MatX& X) {
  const int n = static_cast<int>(A.rows());
  Spectra::SparseCholesky<double> cop(C);
  if (cop.info() != Spectra::CompInfo::Successful) throw InputError(owner + ": " + notDefinite);
  Spectra::SparseSymMatProd<double> mop(A);
  // an even Krylov subspace of 2 nev + 2 (at least 20): the odd 2 nev + 1 stalled the same
  // Lanczos in the linearisation's modes (analysis/linearization.cpp) at 9 of 10 values
  const int ncv = std::min(n, std::max(2 * nev + 2, 20));
  Spectra::SymGEigsSolver<Spectra::SparseSymMatProd<double>, Spectra::SparseCholesky<double>,
                          Spectra::GEigsMode::Cholesky>
      eigs(mop, cop, nev, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-13);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw InputError(owner + ": the " + solver + " eigensolver (Spectra's Lanczos on the pencil, Cholesky mode, " +
                     std::to_string(ncv) + " Krylov vectors) did not find " + std::to_string(nev) +
                     " eigenvalues in 1000 restarts; ask for fewer modes");
  }
  nu = eigs.eigenvalues();
  X = eigs.eigenvectors();
}

}  // namespace

MatX freeFreeModes(const SpMat& K, const SpMat& M, const MatX& rigid, int count, const std::string& owner,
                   VecX* omega, VecX* rigidEigenvalues) {
  const int n = static_cast<int>(K.rows());
  if (count < 1 || count + 6 >= n) {
    throw InputError(owner + ": " + std::to_string(count) + " free-free modes asked of " + std::to_string(n) +
                     " DOF; expected 1 to " + std::to_string(n - 7) + " (six rigid-body modes are dropped)");
  }
  // The shift: below zero by 1e-4 of the mean diagonal ratio tr K / tr M, far from the
  // rigid eigenvalues' round-off (~1e-16 of it) and of the order of the lowest elastic
  // ones, so that the wanted nu are the largest and well separated.
  const double sigma = -1e-4 * std::abs(K.diagonal().sum() / M.diagonal().sum());
  const int nev = count + 6;
  VecX nu;
  MatX X;
  largestOfPencil(M, K - sigma * M, nev, owner,
                  "K - sigma M is not positive definite at sigma = " + std::to_string(sigma) +
                      "; expected a free-free stiffness (positive semi-definite) and a mass with positive total mass",
                  "free-free", nu, X);
  // nu descending: lambda = sigma + 1 / nu ascending where nu > 0
  VecX lambda(nev);
  for (int i = 0; i < nev; ++i) {
    if (!(nu[i] > 0.0)) {
      throw InputError(owner + ": the mass matrix gives a mode of negative mass among the lowest " +
                       std::to_string(nev) + "; expected a mass positive on the low modes");
    }
    lambda[i] = sigma + 1.0 / nu[i];
  }
  // six rigid-body modes: |lambda| <= 1e-6 lambda_7 (a rigid mode's eigenvalue is the
  // round-off of K, ~1e-16 of its largest; the rotor's measure 1e-11 of lambda_7)
  constexpr double kRigidFraction = 1e-6;
  int rigidCount = 0;
  for (int i = 0; i < nev; ++i) rigidCount += std::abs(lambda[i]) <= kRigidFraction * std::abs(lambda[6]) ? 1 : 0;
  if (rigidCount != 6 || !(lambda[6] > 0.0)) {
    throw InputError(owner + ": the free-free body has " + std::to_string(rigidCount) +
                     " rigid-body modes (|lambda| <= 1e-6 lambda_7, lambda_7 = " + std::to_string(lambda[6]) +
                     "); expected exactly six (fewer: supports in the exported stiffness; more: a mechanism or "
                     "disconnected parts)");
  }
  if (rigidEigenvalues != nullptr) *rigidEigenvalues = lambda.head(6);
  MatX phi = X.middleCols(6, count);
  // mean axes exactly: phi -= R (R^T M R)^-1 R^T M phi
  const MatX MR = M * rigid;
  phi -= rigid * (rigid.transpose() * MR).ldlt().solve(MR.transpose() * phi);
  // mass-normalise: phi L^-T with L L^T = phi^T M phi (the modes are M-orthogonal to
  // round-off, so this only scales them)
  const MatX mphi = phi.transpose() * (M * phi);
  const Eigen::LLT<MatX> llt(mphi);
  if (llt.info() != Eigen::Success) throw InputError(owner + ": the elastic modes have no positive mass");
  phi = llt.matrixU().solve<Eigen::OnTheRight>(phi);
  if (omega != nullptr) omega->resize(count);
  for (int i = 0; i < count && omega != nullptr; ++i) (*omega)[i] = std::sqrt(lambda[6 + i]);
  fixModeSigns(phi);
  return phi;
}

MatX clampedModes(const SpMat& K, const SpMat& M, const std::vector<int>& held, int count, const std::string& owner,
                  VecX* omega) {
  const int n = static_cast<int>(K.rows());
  std::vector<char> isHeld(n, 0);
  for (int i : held) {
    if (i < 0 || i >= n || isHeld[i]) {
      throw InputError(owner + ": held DOF " + std::to_string(i) +
                       " is out of range or given twice; expected distinct DOF from 0 to " + std::to_string(n - 1));
    }
    isHeld[i] = 1;
  }
  std::vector<int> freeDofs;  // the kept DOF, ascending; position in the clamped problem
  std::vector<int> position(n, -1);
  for (int i = 0; i < n; ++i) {
    if (!isHeld[i]) {
      position[i] = static_cast<int>(freeDofs.size());
      freeDofs.push_back(i);
    }
  }
  const int nf = static_cast<int>(freeDofs.size());
  if (count < 1 || count >= nf) {
    throw InputError(owner + ": " + std::to_string(count) + " clamped modes asked of " + std::to_string(nf) +
                     " free DOF; expected 1 to " + std::to_string(nf - 1));
  }
  // K_ff, M_ff: the rows and columns of the free DOF (P^T K P, P the selection)
  std::vector<Eigen::Triplet<double>> tp;
  for (int i = 0; i < nf; ++i) tp.emplace_back(freeDofs[i], i, 1.0);
  SpMat P(n, nf);
  P.setFromTriplets(tp.begin(), tp.end());
  const SpMat Kf = P.transpose() * K * P, Mf = P.transpose() * M * P;
  // K_ff is positive definite once the supports hold every rigid motion: the shift
  // sigma = 0 (C = K_ff) and M_ff phi = nu K_ff phi, nu = 1 / lambda; M_ff never factored
  VecX nu;
  MatX X;
  largestOfPencil(Mf, Kf, count, owner,
                  "the clamped stiffness K_ff is not positive definite; expected supports that hold every rigid "
                  "motion of the body",
                  "clamped", nu, X);
  if (omega != nullptr) omega->resize(count);
  MatX phi = MatX::Zero(n, count);
  for (int j = 0; j < count; ++j) {
    // nu > 0: a mode of positive mass (phi^T M phi = nu phi^T K phi); the negative-mass
    // modes of an indefinite M have nu < 0 and come last
    if (!(nu[j] > 0.0)) {
      throw InputError(owner + ": only " + std::to_string(j) + " clamped modes of positive mass; expected " +
                       std::to_string(count));
    }
    const VecX x = X.col(j) / std::sqrt(X.col(j).dot(Mf * X.col(j)));  // mass-normalised
    for (int i = 0; i < nf; ++i) phi(freeDofs[i], j) = x[i];
    if (omega != nullptr) (*omega)[j] = std::sqrt(1.0 / nu[j]);  // lambda = 1 / nu
  }
  fixModeSigns(phi);
  return phi;
}

MatX interfaceConditions(const SpMat& B2, int nodeDofs, const std::vector<int>& nodes, const std::string& owner,
                         std::vector<int>& dofs) {
  const int nn = static_cast<int>(B2.rows()) / nodeDofs;
  if (nodes.empty()) throw InputError(owner + ": craig_bampton reduction needs at least one interface node");
  std::vector<int> sorted = nodes;
  std::sort(sorted.begin(), sorted.end());
  for (int n : sorted) {
    if (n < 0 || n >= nn) {
      throw InputError(owner + ": interface node " + std::to_string(n) + " does not exist (nodes 0.." +
                       std::to_string(nn - 1) + ")");
    }
  }
  const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
  if (twice != sorted.end()) {
    throw InputError(owner + ": interface node " + std::to_string(*twice) + " is listed twice");
  }
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = B2;
  dofs.clear();
  MatX G = MatX::Zero(static_cast<Eigen::Index>(nodes.size()) * nodeDofs, B2.cols());
  for (int n : nodes) {
    for (int k = 0; k < nodeDofs; ++k) {
      const int r = static_cast<int>(dofs.size());
      dofs.push_back(nodeDofs * n + k);
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, dofs.back()); it; ++it) {
        G(r, it.col()) = it.value();
      }
    }
  }
  return G;
}

CraigBamptonBasis craigBamptonBasis(const SpMat& K, const SpMat& M, const MatX& G, const std::vector<int>& keep,
                                    const std::string& owner) {
  CraigBamptonBasis cb;
  // interface coordinates: the rows of G independent of the earlier ones; a zero row is
  // a coordinate the reference conditions already hold (no constraint mode)
  const std::vector<int> dependent = dependentRows(G);
  for (int r = 0; r < G.rows(); ++r) {
    if (!std::binary_search(dependent.begin(), dependent.end(), r)) cb.interfaceRows.push_back(r);
  }
  const int n = static_cast<int>(K.rows()), nc = static_cast<int>(cb.interfaceRows.size());
  MatX Gi(nc, n);
  for (int k = 0; k < nc; ++k) Gi.row(k) = G.row(cb.interfaceRows[k]);

  // constraint modes (CraigBampton1968): K Psi = Gi^T Lambda, Gi Psi = I, so
  // Psi = K^-1 Gi^T (Gi K^-1 Gi^T)^-1 (static condensation on the interface)
  MatX Psi(n, nc);
  if (nc > 0) {
    const Eigen::SimplicialLDLT<SpMat> ldlt(K);
    if (ldlt.info() != Eigen::Success) throw ModelError(owner + ": craig_bampton: the stiffness K_ff is singular");
    const MatX Y = ldlt.solve(MatX(Gi.transpose()));
    const MatX S = Gi * Y;  // the interface flexibility, symmetric positive definite
    Psi = Y * S.llt().solve(MatX::Identity(nc, nc));
  }

  // fixed-interface normal modes (CraigBampton1968): K, M restricted to null(Gi)
  const MatX Z = nc > 0 ? nullSpaceBasis(Gi) : MatX(MatX::Identity(n, n));
  const MatX KZ = K * Z, MZ = M * Z;
  const MatX Kz = Z.transpose() * KZ, Mz = Z.transpose() * MZ;
  const MatX phi = normalModes(Kz, Mz, keep, owner, &cb.fixedInterfaceFrequencies, "fixed-interface mode");

  cb.basis.resize(n, nc + static_cast<Eigen::Index>(keep.size()));
  cb.basis.leftCols(nc) = Psi;
  cb.basis.rightCols(keep.size()) = Z * phi;
  return cb;
}

MatX withStaticModes(const SpMat& K, const SpMat& M, const MatX& basis, const MatX& F) {
  const Eigen::SimplicialLDLT<SpMat> ldlt(K);
  return withStaticResponses(K, M, basis, ldlt.solve(F));  // static responses K y = f
}

MatX withStaticResponses(const SpMat& K, const SpMat& M, const MatX& basis, MatX Y) {
  double largest = 0.0;    // strain energy scale y^T K y of the largest static response
  for (int j = 0; j < Y.cols(); ++j) largest = std::max(largest, Y.col(j).dot(K * Y.col(j)));
  if (!(largest > 0.0)) return basis;
  if (basis.cols() > 0) {  // Y - B (B^T K B)^-1 B^T K Y: the part K-orthogonal to the basis
    const MatX KB = K * basis;
    const MatX Kbb = basis.transpose() * KB;
    Y -= basis * Kbb.ldlt().solve(KB.transpose() * Y);
  }
  const MatX KY = K * Y;
  const MatX Kyy = 0.5 * (Y.transpose() * KY + KY.transpose() * Y);
  const Eigen::SelfAdjointEigenSolver<MatX> es(Kyy);
  std::vector<int> kept;
  for (int k = 0; k < Kyy.rows(); ++k) {
    if (es.eigenvalues()[k] > 1e-12 * largest) kept.push_back(k);
  }
  MatX out(basis.rows(), basis.cols() + static_cast<Eigen::Index>(kept.size()));
  out.leftCols(basis.cols()) = basis;
  for (size_t k = 0; k < kept.size(); ++k) {
    VecX y = Y * es.eigenvectors().col(kept[k]);
    y /= std::sqrt(y.dot(M * y));  // mass-normalised
    out.col(basis.cols() + static_cast<Eigen::Index>(k)) = y;
  }
  return out;
}

MatX freeStaticResponses(const SpMat& K, const SpMat& M, const MatX& R, const MatX& F, const std::string& owner) {
  const int n = static_cast<int>(K.rows()), r = static_cast<int>(R.cols());
  const MatX MR = M * R;
  const MatX relieved = F - MR * (R.transpose() * MR).ldlt().solve(R.transpose() * F);  // inertia relief
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < K.outerSize(); ++j) {
    for (SpMat::InnerIterator it(K, j); it; ++it) t.emplace_back(it.row(), j, it.value());
  }
  for (int j = 0; j < r; ++j) {
    for (int i = 0; i < n; ++i) {
      if (MR(i, j) == 0.0) continue;
      t.emplace_back(i, n + j, MR(i, j));
      t.emplace_back(n + j, i, MR(i, j));
    }
  }
  SpMat A(n + r, n + r);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SparseLU<SpMat> lu;
  lu.compute(A);
  if (lu.info() != Eigen::Success) {
    throw InputError(owner + ": the stiffness has a zero-energy motion besides the six rigid ones (a mechanism); "
                     "the static responses to the inertia loads are undefined");
  }
  MatX rhs = MatX::Zero(n + r, F.cols());
  rhs.topRows(n) = relieved;
  const MatX y = lu.solve(rhs);
  return y.topRows(n);
}

}  // namespace flexmbd
