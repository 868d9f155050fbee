#include "bodies/ffr_invariants_3d.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <sstream>

#include "bodies/invariant_checks.hpp"
#include "core/errors.hpp"

namespace flexmbd {

using namespace invariantchecks;

namespace {

const char* kAxis[3] = {"x", "y", "z"};

std::string sklName(int k, int l) { return std::string("s_") + kAxis[k] + kAxis[l]; }
std::string rklName(int k, int l) { return std::string("r_") + kAxis[k] + kAxis[l]; }
std::string hName(int i) { return std::string("h_") + kAxis[i]; }
std::string gklName(int k, int l) { return std::string("spin_stiffness_") + kAxis[k] + kAxis[l]; }

/// An optional invariant: absent (0 x 0) or n x n, finite and symmetric.
void requireOptionalSymmetric(const SpMat& A, int n, const std::string& owner, const std::string& name) {
  if (A.size() == 0) return;
  const std::string sz = std::to_string(n);
  requireSize(A.rows() == n && A.cols() == n, owner, name, sz + " x " + sz + " (or absent)");
  requireFiniteAll(A, owner, name);
  requireSymmetric(A, owner, name);
}

}  // namespace

void FfrInvariants3d::validate(const std::string& owner) const {
  const int n = numElastic();
  const std::string sz = std::to_string(n);
  validateMass(owner);
  requireFiniteAll(MatX(secondMoment), owner, "second_moment");
  validateSizes(owner);
  for (int k = 0; k < 3; ++k) {
    requireSize(positionShape[k].cols() == n, owner, std::string("position_shape_") + kAxis[k], "3 x " + sz);
    for (int l = 0; l < 3; ++l) {
      requireSize(sKL[k][l].rows() == n && sKL[k][l].cols() == n, owner, sklName(k, l), sz + " x " + sz);
    }
  }
  validateFinite(owner);
  for (int k = 0; k < 3; ++k) {
    requireFiniteAll(positionShape[k], owner, std::string("position_shape_") + kAxis[k]);
    for (int l = 0; l < 3; ++l) requireFiniteAll(sKL[k][l], owner, sklName(k, l));
  }
  validateSectionRotation(owner);
  validateSymmetry(owner);
  for (int k = 0; k < 3; ++k) requireSymmetric(sKL[k][k], owner, sklName(k, k));
  validateTransposedPairs(owner);
  validateDefiniteness(owner);
  validateSecondMoment(owner);
  validatePoints(owner);
}

void FfrInvariants3d::validateTransposedPairs(const std::string& owner) const {
  if (numElastic() == 0) return;
  const double scale = maxAbs(mff) + 1e-300;
  for (int k = 0; k < 3; ++k) {
    for (int l = k + 1; l < 3; ++l) {
      if (maxAbs(SpMat(sKL[l][k] - SpMat(sKL[k][l].transpose()))) > 1e-10 * scale) {
        throw InputError(owner + ": invariant " + sklName(l, k) + " is not the transpose of " + sklName(k, l) +
                         "; expected S_lk = S_kl^T");
      }
    }
  }
}

void FfrInvariants3d::validateSecondMoment(const std::string& owner) const {
  // second moment J = int rho u0 u0^T: symmetric positive semi-definite
  const double trJ = secondMoment.trace();
  if ((secondMoment - secondMoment.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (std::abs(trJ) + 1e-300)) {
    throw InputError(owner + ": invariant second_moment is not symmetric; expected int rho u0 u0^T dV");
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> es(secondMoment, Eigen::EigenvaluesOnly);
  if (es.eigenvalues().minCoeff() < -1e-12 * std::abs(trJ)) {
    std::ostringstream os;
    os << owner << ": invariant second_moment has the negative eigenvalue " << es.eigenvalues().minCoeff()
       << "; expected a positive semi-definite int rho u0 u0^T dV";
    throw InputError(os.str());
  }
  // m tr(J) >= |int rho u0 dV|^2: the inertia about the centre of mass is not negative
  if (mass * trJ < firstMoment.squaredNorm() * (1.0 - 1e-12)) {
    std::ostringstream os;
    os << owner << ": invariant second_moment has trace " << trJ << ", smaller than |first_moment|^2 / mass = "
       << firstMoment.squaredNorm() / mass << " (negative inertia about the centre of mass)";
    throw InputError(os.str());
  }
}

void FfrInvariants3d::validateSectionRotation(const std::string& owner) const {
  const int n = numElastic();
  for (int i = 0; i < 3; ++i) requireOptionalSymmetric(hI[i], n, owner, hName(i));
  validateSymmetricPairs(rKL, rklName, owner);
  validateSymmetricPairs(spinStiffness, gklName, owner);
}

void FfrInvariants3d::validateSymmetricPairs(const std::array<std::array<SpMat, 3>, 3>& pairs,
                                             std::string (*name)(int, int), const std::string& owner) const {
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      const SpMat& R = pairs[k][l];
      if (R.size() == 0) continue;  // none
      requireOptionalSymmetric(R, numElastic(), owner, name(k, l));
      if (l != k && (pairs[l][k].size() == 0 || maxAbs(SpMat(pairs[l][k] - R)) > 0.0)) {
        throw InputError(owner + ": invariant " + name(l, k) + " differs from " + name(k, l) + "; expected the " +
                         "two to be equal");
      }
    }
  }
}

MatX FfrInvariants3d::inertiaLoads() const {
  MatX F(numElastic(), 12);
  F.leftCols(3) = sBar.transpose();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) F.col(3 + 3 * k + l) = positionShape[k].row(l).transpose();
  }
  return F;
}

FfrInvariants3d FfrInvariants3d::transformed(const SpMat& P) const {
  FfrInvariants3d r;
  transformInto(P, r);
  r.secondMoment = secondMoment;
  const SpMat Pt = P.transpose();
  for (int k = 0; k < 3; ++k) {
    r.positionShape[k] = positionShape[k] * P;
    for (int l = 0; l < 3; ++l) {
      r.sKL[k][l] = Pt * sKL[k][l] * P;
      if (rKL[k][l].size() != 0) r.rKL[k][l] = Pt * rKL[k][l] * P;
      if (spinStiffness[k][l].size() != 0) r.spinStiffness[k][l] = Pt * spinStiffness[k][l] * P;
    }
    if (hI[k].size() != 0) r.hI[k] = Pt * hI[k] * P;
  }
  return r;
}

}  // namespace flexmbd
