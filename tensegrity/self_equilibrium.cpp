// GCC 12 flags Eigen's triangular matrix-vector kernel, instantiated by the QR
// preconditioner of JacobiSVD, with a false -Wmaybe-uninitialized; silenced for this
// file only (the pragma must precede the first inclusion of Eigen).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "tensegrity/self_equilibrium.hpp"

#include <Eigen/SVD>
#include <sstream>

#include "core/errors.hpp"

namespace flexmbd {

MatX equilibriumMatrix(const TensegrityStructure& s, const VecX& x) {
  const int d = s.dimension();
  const std::vector<MemberRef> members = s.members();
  MatX full = MatX::Zero(s.numCoordinates(), static_cast<int>(members.size()));
  for (std::size_t j = 0; j < members.size(); ++j) {
    const auto [i, k] = s.memberNodes(members[j]);
    const VecX dik = x.segment(d * i, d) - x.segment(d * k, d);
    full.col(j).segment(d * i, d) = dik;
    full.col(j).segment(d * k, d) = -dik;
  }
  MatX A(s.numFreeCoordinates(), full.cols());
  for (int a = 0; a < s.numFreeCoordinates(); ++a) A.row(a) = full.row(s.freeCoordinates()[a]);
  return A;
}

SelfStressStates computeSelfStress(const TensegrityStructure& s, const VecX& x, double relativeTolerance) {
  const MatX A = equilibriumMatrix(s, x);
  const int m = static_cast<int>(A.cols());
  Eigen::JacobiSVD<MatX> svd(A, Eigen::ComputeFullV);
  SelfStressStates out;
  out.singularValues = svd.singularValues();
  const double smax = out.singularValues.size() > 0 ? out.singularValues[0] : 0.0;
  int rank = 0;
  for (int k = 0; k < out.singularValues.size(); ++k) {
    if (out.singularValues[k] > relativeTolerance * smax) ++rank;
  }
  out.rank = rank;
  out.mechanisms = s.numFreeCoordinates() - rank;
  out.forceDensities = svd.matrixV().rightCols(m - rank);
  return out;
}

void applyPrestress(TensegrityStructure& s, const VecX& q, double scale) {
  const std::vector<MemberRef> members = s.members();
  if (q.size() != static_cast<int>(members.size())) {
    throw InputError("prestress: expected one force density per member (" + std::to_string(members.size()) + ")");
  }
  const VecX x = s.initialPositions();
  const int d = s.dimension();
  for (std::size_t j = 0; j < members.size(); ++j) {
    const auto [i, k] = s.memberNodes(members[j]);
    const double l = (x.segment(d * i, d) - x.segment(d * k, d)).norm();
    const double t = scale * q[j] * l;  // member force t = q l (tension positive)
    std::ostringstream os;
    os.precision(6);
    os << t;
    if (members[j].isStrut) {
      const TensegrityStrut& st = s.strut(members[j].index);
      if (t > 0.0) throw InputError("prestress: strut \"" + st.name + "\" would be in tension (" + os.str() + ")");
      if (!(1.0 + t / st.axialStiffness > 0.0)) {
        throw InputError("prestress: strut \"" + st.name + "\" cannot carry " + os.str() + " (more than its EA)");
      }
      s.setStrutNaturalLength(members[j].index, l / (1.0 + t / st.axialStiffness));
    } else {
      const TensegrityCable& c = s.cable(members[j].index);
      if (t < 0.0) throw InputError("prestress: cable \"" + c.name + "\" would be compressed (" + os.str() + ")");
      s.setCableNaturalLength(members[j].index, c.inextensible ? l : l / (1.0 + t / c.axialStiffness));
    }
  }
}

}  // namespace flexmbd

#pragma GCC diagnostic pop
