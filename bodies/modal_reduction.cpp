#include "bodies/modal_reduction.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

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
  return Phi;
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

  // constraint modes (Craig & Bampton 1968): K Psi = Gi^T Lambda, Gi Psi = I, so
  // Psi = K^-1 Gi^T (Gi K^-1 Gi^T)^-1 (static condensation on the interface)
  MatX Psi(n, nc);
  if (nc > 0) {
    const Eigen::SimplicialLDLT<SpMat> ldlt(K);
    if (ldlt.info() != Eigen::Success) throw ModelError(owner + ": craig_bampton: the stiffness K_ff is singular");
    const MatX Y = ldlt.solve(MatX(Gi.transpose()));
    const MatX S = Gi * Y;  // the interface flexibility, symmetric positive definite
    Psi = Y * S.llt().solve(MatX::Identity(nc, nc));
  }

  // fixed-interface normal modes (Craig & Bampton 1968): K, M restricted to null(Gi)
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
  MatX Y = ldlt.solve(F);  // static responses K y = f
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

}  // namespace flexmbd
