#include "bodies/ffr_invariants.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <sstream>

#include "bodies/invariant_checks.hpp"
#include "core/errors.hpp"

namespace flexmbd {

using namespace invariantchecks;

void FfrInvariants::validate(const std::string& owner) const {
  const int n = numElastic();
  requirePositive(mass, owner + ": invariant mass");
  requireFinite(firstMoment.x(), owner + ": invariant first_moment");
  requireFinite(firstMoment.y(), owner + ": invariant first_moment");
  requireFinite(polarMoment, owner + ": invariant polar_moment");
  const std::string sz = std::to_string(n);
  requireSize(mff.cols() == n, owner, "m_ff", sz + " x " + sz);
  requireSize(sBar.cols() == n, owner, "s_bar", "2 x " + sz);
  requireSize(i1.size() == n, owner, "i1", sz);
  requireSize(j0.size() == n, owner, "j0", sz);
  requireSize(sTilde.rows() == n && sTilde.cols() == n, owner, "s_tilde", sz + " x " + sz);
  requireSize(kff.rows() == n && kff.cols() == n, owner, "k_ff", sz + " x " + sz);
  requireSize(dff.rows() == n && dff.cols() == n, owner, "d_ff", sz + " x " + sz);
  for (auto [A, name] : {std::pair<const SpMat*, const char*>{&mff, "m_ff"}, {&kff, "k_ff"}, {&dff, "d_ff"},
                         {&sTilde, "s_tilde"}}) {
    requireFiniteAll(*A, owner, name);
  }
  requireFiniteAll(sBar, owner, "s_bar");
  requireFiniteAll(i1, owner, "i1");
  requireFiniteAll(j0, owner, "j0");
  requireSymmetric(mff, owner, "m_ff");
  requireSymmetric(kff, owner, "k_ff");
  requireSymmetric(dff, owner, "d_ff");
  if (n > 0) {
    const double scale = maxAbs(sTilde) + maxAbs(mff);
    if (maxAbs(SpMat(sTilde + SpMat(sTilde.transpose()))) > 1e-10 * scale) {
      throw InputError(owner + ": invariant s_tilde is not skew-symmetric; expected S~ = -S~^T");
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
  if (polarMoment < firstMoment.squaredNorm() / mass * (1.0 - 1e-12)) {
    std::ostringstream os;
    os << owner << ": invariant polar_moment " << polarMoment
       << " is smaller than |first_moment|^2 / mass = " << firstMoment.squaredNorm() / mass
       << " (negative inertia about the centre of mass)";
    throw InputError(os.str());
  }
  for (size_t k = 0; k < points.size(); ++k) {
    requireSize(points[k].shape.cols() == n && points[k].rotationShape.size() == n, owner,
                "shape of point " + std::to_string(k), "2 x " + sz + " and 1 x " + sz);
  }
}

std::vector<int> FfrInvariants::support(const FfrPoint& p) {
  std::vector<int> s;
  for (int k = 0; k < p.shape.cols(); ++k) {
    if (p.shape(0, k) != 0.0 || p.shape(1, k) != 0.0 || p.rotationShape[k] != 0.0) s.push_back(k);
  }
  return s;
}

FfrInvariants FfrInvariants::transformed(const SpMat& P) const {
  FfrInvariants r;
  r.mass = mass;
  r.firstMoment = firstMoment;
  r.polarMoment = polarMoment;
  r.sBar = sBar * P;
  r.i1 = P.transpose() * i1;
  r.j0 = P.transpose() * j0;
  const SpMat Pt = P.transpose();
  r.mff = Pt * mff * P;
  r.sTilde = Pt * sTilde * P;
  r.kff = Pt * kff * P;
  r.dff = Pt * dff * P;
  for (const FfrPoint& p : points) r.points.push_back({p.position, p.shape * P, p.rotationShape * P});
  return r;
}

}  // namespace flexmbd
