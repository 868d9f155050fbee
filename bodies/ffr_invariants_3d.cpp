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
  requirePositive(mass, owner + ": invariant mass");
  for (int k = 0; k < 3; ++k) requireFinite(firstMoment[k], owner + ": invariant first_moment");
  requireFiniteAll(MatX(secondMoment), owner, "second_moment");
  const std::string sz = std::to_string(n);
  requireSize(mff.cols() == n, owner, "m_ff", sz + " x " + sz);
  requireSize(sBar.cols() == n, owner, "s_bar", "3 x " + sz);
  for (int k = 0; k < 3; ++k) {
    requireSize(positionShape[k].cols() == n, owner, std::string("position_shape_") + kAxis[k], "3 x " + sz);
    for (int l = 0; l < 3; ++l) {
      requireSize(sKL[k][l].rows() == n && sKL[k][l].cols() == n, owner, sklName(k, l), sz + " x " + sz);
    }
  }
  requireSize(kff.rows() == n && kff.cols() == n, owner, "k_ff", sz + " x " + sz);
  requireSize(dff.rows() == n && dff.cols() == n, owner, "d_ff", sz + " x " + sz);
  for (auto [A, name] : {std::pair<const SpMat*, const char*>{&mff, "m_ff"}, {&kff, "k_ff"}, {&dff, "d_ff"}}) {
    requireFiniteAll(*A, owner, name);
  }
  requireFiniteAll(sBar, owner, "s_bar");
  for (int k = 0; k < 3; ++k) {
    requireFiniteAll(positionShape[k], owner, std::string("position_shape_") + kAxis[k]);
    for (int l = 0; l < 3; ++l) requireFiniteAll(sKL[k][l], owner, sklName(k, l));
  }
  validateSectionRotation(owner);
  requireSymmetric(mff, owner, "m_ff");
  requireSymmetric(kff, owner, "k_ff");
  requireSymmetric(dff, owner, "d_ff");
  for (int k = 0; k < 3; ++k) requireSymmetric(sKL[k][k], owner, sklName(k, k));
  if (n > 0) {
    const double scale = maxAbs(mff) + 1e-300;
    for (int k = 0; k < 3; ++k) {
      for (int l = k + 1; l < 3; ++l) {
        if (maxAbs(SpMat(sKL[l][k] - SpMat(sKL[k][l].transpose()))) > 1e-10 * scale) {
          throw InputError(owner + ": invariant " + sklName(l, k) + " is not the transpose of " + sklName(k, l) +
                           "; expected S_lk = S_kl^T");
        }
      }
    }
    if (!isPositiveDefinite(mff)) {
      throw InputError(owner + ": invariant m_ff is not positive definite; expected a positive definite mass matrix");
    }
    if (!isPositiveDefinite(kff)) {
      throw InputError(owner +
                       ": the stiffness matrix k_ff is not positive definite: the reference conditions leave a "
                       "rigid-body mode (expected conditions that fix the body frame: pinned_pinned, clamped or "
                       "free_free)");
    }
    // D_ff + eps I positive definite <=> D_ff positive semi-definite up to eps
    SpMat shifted(n, n);
    shifted.setIdentity();
    shifted = dff + (1e-10 * (maxAbs(dff) + 1e-300)) * shifted;
    if (maxAbs(dff) > 0.0 && !isPositiveDefinite(shifted)) {
      throw InputError(owner + ": invariant d_ff is not positive semi-definite; damping would add energy");
    }
  }
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
  if (mass * trJ < firstMoment.squaredNorm() * (1.0 - 1e-12)) {
    std::ostringstream os;
    os << owner << ": invariant second_moment has trace " << trJ << ", smaller than |first_moment|^2 / mass = "
       << firstMoment.squaredNorm() / mass << " (negative inertia about the centre of mass)";
    throw InputError(os.str());
  }
  for (size_t k = 0; k < points.size(); ++k) {
    requireSize(points[k].shape.cols() == n && points[k].rotationShape.cols() == n, owner,
                "shape of point " + std::to_string(k), "3 x " + sz + " (shape and rotation shape)");
    if (!points[k].position.allFinite() || !points[k].shape.allFinite() || !points[k].rotationShape.allFinite()) {
      throw InputError(owner + ": invariant point " + std::to_string(k) + " has entries that are not finite");
    }
  }
}

void FfrInvariants3d::validateSectionRotation(const std::string& owner) const {
  const int n = numElastic();
  for (int i = 0; i < 3; ++i) requireOptionalSymmetric(hI[i], n, owner, hName(i));
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      const SpMat& R = rKL[k][l];
      if (R.size() == 0) continue;  // none
      requireOptionalSymmetric(R, n, owner, rklName(k, l));
      if (l != k && (rKL[l][k].size() == 0 || maxAbs(SpMat(rKL[l][k] - R)) > 0.0)) {
        throw InputError(owner + ": invariant " + rklName(l, k) + " differs from " + rklName(k, l) +
                         "; expected R_lk = R_kl");
      }
    }
  }
}

std::vector<int> FfrInvariants3d::support(const FfrPoint3d& p) {
  std::vector<int> s;
  for (int k = 0; k < p.shape.cols(); ++k) {
    if (!p.shape.col(k).isZero(0.0) || (k < p.rotationShape.cols() && !p.rotationShape.col(k).isZero(0.0))) {
      s.push_back(k);
    }
  }
  return s;
}

FfrInvariants3d FfrInvariants3d::transformed(const SpMat& P) const {
  FfrInvariants3d r;
  r.mass = mass;
  r.firstMoment = firstMoment;
  r.secondMoment = secondMoment;
  r.sBar = sBar * P;
  const SpMat Pt = P.transpose();
  for (int k = 0; k < 3; ++k) {
    r.positionShape[k] = positionShape[k] * P;
    for (int l = 0; l < 3; ++l) {
      r.sKL[k][l] = Pt * sKL[k][l] * P;
      if (rKL[k][l].size() != 0) r.rKL[k][l] = Pt * rKL[k][l] * P;
    }
    if (hI[k].size() != 0) r.hI[k] = Pt * hI[k] * P;
  }
  r.mff = Pt * mff * P;
  r.kff = Pt * kff * P;
  r.dff = Pt * dff * P;
  for (const FfrPoint3d& p : points) r.points.push_back({p.position, p.shape * P, p.rotationShape * P});
  return r;
}

}  // namespace flexmbd
