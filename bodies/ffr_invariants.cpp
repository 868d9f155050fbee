#include "bodies/ffr_invariants.hpp"

#include <sstream>

#include "bodies/invariant_checks.hpp"
#include "core/errors.hpp"

namespace flexmbd {

using namespace invariantchecks;

void FfrInvariants::validate(const std::string& owner) const {
  const int n = numElastic();
  const std::string sz = std::to_string(n);
  validateMass(owner);
  requireFinite(polarMoment, owner + ": invariant polar_moment");
  validateSizes(owner);
  requireSize(i1.size() == n, owner, "i1", sz);
  requireSize(j0.size() == n, owner, "j0", sz);
  requireSize(sTilde.rows() == n && sTilde.cols() == n, owner, "s_tilde", sz + " x " + sz);
  requireSize(rff.size() == 0 || (rff.rows() == n && rff.cols() == n), owner, "r", sz + " x " + sz + " or none");
  validateFinite(owner);
  requireFiniteAll(rff, owner, "r");
  requireFiniteAll(sTilde, owner, "s_tilde");
  requireFiniteAll(i1, owner, "i1");
  requireFiniteAll(j0, owner, "j0");
  validateSymmetry(owner);
  // S~ = -S~^T
  if (n > 0 && maxAbs(SpMat(sTilde + SpMat(sTilde.transpose()))) > 1e-10 * (maxAbs(sTilde) + maxAbs(mff))) {
    throw InputError(owner + ": invariant s_tilde is not skew-symmetric; expected S~ = -S~^T");
  }
  if (n > 0 && rff.size() != 0 && maxAbs(SpMat(rff - SpMat(rff.transpose()))) > 1e-10 * (maxAbs(rff) + maxAbs(mff))) {
    throw InputError(owner + ": invariant r is not symmetric; expected R = R^T");
  }
  validateDefiniteness(owner);
  // I0 >= |int rho u0 dV|^2 / m: the polar moment about the centre of mass is not negative
  if (polarMoment < firstMoment.squaredNorm() / mass * (1.0 - 1e-12)) {
    std::ostringstream os;
    os << owner << ": invariant polar_moment " << polarMoment
       << " is smaller than |first_moment|^2 / mass = " << firstMoment.squaredNorm() / mass
       << " (negative inertia about the centre of mass)";
    throw InputError(os.str());
  }
  validatePoints(owner);
}

FfrInvariants FfrInvariants::transformed(const SpMat& P) const {
  FfrInvariants r;
  transformInto(P, r);
  r.polarMoment = polarMoment;
  r.i1 = P.transpose() * i1;
  r.j0 = P.transpose() * j0;
  r.sTilde = SpMat(P.transpose()) * sTilde * P;
  if (rff.size() != 0) r.rff = SpMat(P.transpose()) * rff * P;
  return r;
}

SpMat FfrInvariants::polarQuadratic() const { return rff.size() == 0 ? mff : SpMat(mff + rff); }

}  // namespace flexmbd
