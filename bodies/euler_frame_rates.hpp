/// @file
/// The kinematic equation q' = T(q) v (Nikravesh1988, eq. 6.41) of a spatial body whose coordinates start with a
/// frame (R, p): origin R (world) and Euler parameters p, with velocities (R' world,
/// w body axes), followed by `extra` coordinates that are their own velocities' integrals
/// (elastic coordinates). Shared by RigidBody3d (extra = 0) and FfrBody3d (extra = nf).
#pragma once

#include "core/matrix_sink.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

/// T+ of the rotation block: 2 L(p) / |p|^2 (3 x 4), the body-axes rotation of an
/// increment dp (Nikravesh1988, eq. 6.41, with the gauge |p| divided out).
inline Mat34 eulerRateInverse(const ConstVecRef& q) {
  const Vec4 p = q.segment<4>(3);
  return (2.0 / p.squaredNorm()) * quaternionL(p);
}

/// T = diag(I3, 1/2 L(p)^T, I_extra) ((7 + extra) x (6 + extra)), its 15 + extra
/// structural non-zeros (p' = 1/2 L^T w, Nikravesh1988, eq. 6.41).
inline void addEulerFrameRateMatrix(const ConstVecRef& q, int extra, const MatrixSink& T) {
  for (int k = 0; k < 3; ++k) T.add(k, k, 1.0);
  T.addBlock(3, 3, 0.5 * quaternionL(q.segment<4>(3)).transpose());
  for (int k = 0; k < extra; ++k) T.add(7 + k, 6 + k, 1.0);
}

/// T+ = diag(I3, 2 L(p) / |p|^2, I_extra) ((6 + extra) x (7 + extra)), structural
/// non-zeros only.
inline void addEulerFrameRateInverse(const ConstVecRef& q, int extra, const MatrixSink& Tinv) {
  for (int k = 0; k < 3; ++k) Tinv.add(k, k, 1.0);
  Tinv.addBlock(3, 3, eulerRateInverse(q));
  for (int k = 0; k < extra; ++k) Tinv.add(6 + k, 7 + k, 1.0);
}

}  // namespace flexmbd
