#include "bodies/ffr_invariants_base.hpp"

#include <Eigen/Dense>

#include "bodies/invariant_checks.hpp"
#include "core/errors.hpp"

namespace flexmbd {

using namespace invariantchecks;

template <int Dim>
std::vector<int> FfrInvariantsBase<Dim>::support(const Point& p) {
  std::vector<int> s;
  for (int k = 0; k < p.shape.cols(); ++k) {
    if (!p.shape.col(k).isZero(0.0) || (k < p.rotationShape.cols() && !p.rotationShape.col(k).isZero(0.0))) {
      s.push_back(k);
    }
  }
  return s;
}

template <int Dim>
void FfrInvariantsBase<Dim>::validateMass(const std::string& owner) const {
  requirePositive(mass, owner + ": invariant mass");
  for (int k = 0; k < Dim; ++k) requireFinite(firstMoment[k], owner + ": invariant first_moment");
}

template <int Dim>
void FfrInvariantsBase<Dim>::validateSizes(const std::string& owner) const {
  const int n = numElastic();
  const std::string sz = std::to_string(n);
  requireSize(mff.cols() == n, owner, "m_ff", sz + " x " + sz);
  requireSize(sBar.cols() == n, owner, "s_bar", std::to_string(Dim) + " x " + sz);
  requireSize(kff.rows() == n && kff.cols() == n, owner, "k_ff", sz + " x " + sz);
  requireSize(dff.rows() == n && dff.cols() == n, owner, "d_ff", sz + " x " + sz);
}

template <int Dim>
void FfrInvariantsBase<Dim>::validateFinite(const std::string& owner) const {
  for (auto [A, name] : {std::pair<const SpMat*, const char*>{&mff, "m_ff"}, {&kff, "k_ff"}, {&dff, "d_ff"}}) {
    requireFiniteAll(*A, owner, name);
  }
  requireFiniteAll(MatX(sBar), owner, "s_bar");
}

template <int Dim>
void FfrInvariantsBase<Dim>::validateSymmetry(const std::string& owner) const {
  requireSymmetric(mff, owner, "m_ff");
  requireSymmetric(kff, owner, "k_ff");
  requireSymmetric(dff, owner, "d_ff");
}

template <int Dim>
void FfrInvariantsBase<Dim>::validateDefiniteness(const std::string& owner) const {
  const int n = numElastic();
  if (n == 0) return;
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

template <int Dim>
void FfrInvariantsBase<Dim>::validatePoints(const std::string& owner) const {
  const std::string sz = std::to_string(numElastic());
  const std::string expected = Dim == 2 ? "2 x " + sz + " and 1 x " + sz
                                        : "3 x " + sz + " (shape and rotation shape)";
  for (size_t k = 0; k < points.size(); ++k) {
    const Point& p = points[k];
    requireSize(p.shape.cols() == numElastic() && p.rotationShape.cols() == numElastic(), owner,
                "shape of point " + std::to_string(k), expected);
    if (!p.position.allFinite() || !p.shape.allFinite() || !p.rotationShape.allFinite()) {
      throw InputError(owner + ": invariant point " + std::to_string(k) + " has entries that are not finite");
    }
  }
}

template <int Dim>
void FfrInvariantsBase<Dim>::transformInto(const SpMat& P, FfrInvariantsBase& r) const {
  r.mass = mass;
  r.firstMoment = firstMoment;
  r.sBar = sBar * P;
  const SpMat Pt = P.transpose();
  // P^T A P of a symmetric A is symmetric; its round-off is not (a dense modal P over a
  // stiff mesh: k_ff's entries ~1e10 against omega^2 ~1e4), so the symmetric part is kept
  const auto congruent = [&](const SpMat& A) {
    const SpMat C = Pt * A * P;
    return SpMat(0.5 * (C + SpMat(C.transpose())));
  };
  r.mff = congruent(mff);
  r.kff = congruent(kff);
  r.dff = congruent(dff);
  r.points.clear();
  for (const Point& p : points) r.points.push_back({p.position, p.shape * P, p.rotationShape * P});
}

template struct FfrInvariantsBase<2>;
template struct FfrInvariantsBase<3>;

}  // namespace flexmbd
