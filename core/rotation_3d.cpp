#include "core/rotation_3d.hpp"

namespace flexmbd {

Vec4 quaternionFromRotation(const Mat3& A) {
  // Shepperd1978: take the largest of 4 e_k^2 from the trace and the diagonal.
  const double tr = A.trace();
  Vec4 d(tr, A(0, 0), A(1, 1), A(2, 2));
  Eigen::Index k = 0;
  d.maxCoeff(&k);
  Vec4 p;
  if (k == 0) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    p << 0.25 * s, (A(2, 1) - A(1, 2)) / s, (A(0, 2) - A(2, 0)) / s, (A(1, 0) - A(0, 1)) / s;
  } else if (k == 1) {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * A(0, 0) - tr);
    p << (A(2, 1) - A(1, 2)) / s, 0.25 * s, (A(0, 1) + A(1, 0)) / s, (A(0, 2) + A(2, 0)) / s;
  } else if (k == 2) {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * A(1, 1) - tr);
    p << (A(0, 2) - A(2, 0)) / s, (A(0, 1) + A(1, 0)) / s, 0.25 * s, (A(1, 2) + A(2, 1)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * A(2, 2) - tr);
    p << (A(1, 0) - A(0, 1)) / s, (A(0, 2) + A(2, 0)) / s, (A(1, 2) + A(2, 1)) / s, 0.25 * s;
  }
  if (p[0] < 0.0) p = -p;
  return p.normalized();
}

}  // namespace flexmbd
