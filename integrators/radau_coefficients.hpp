/// @file
/// The Radau IIA methods with s = 3, 5 and 7 stages (orders 5, 9 and 13) and what the
/// solver derives from each once: the transformation of A^-1 to one real and (s-1)/2
/// complex eigenvalues, the embedded error estimate and the collocation polynomial.
/// Computed, not tabulated: nodes as roots of the Radau polynomial, the rest from them in
/// long double (HairerWanner1996, IV.5 (5.3)-(5.4) and IV.8; HairerWanner1999, sec. 5).
#pragma once

#include <Eigen/Core>

namespace flexmbd {

/// Up to 7 stages, so the small vectors and matrices of a method live on the stack.
inline constexpr int kRadauMaxStages = 7;
using RadauVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kRadauMaxStages, 1>;
using RadauMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kRadauMaxStages, kRadauMaxStages>;

struct RadauCoefficients {
  int stages = 0;  ///< s; the order is 2 s - 1
  int pairs = 0;   ///< (s - 1) / 2 complex eigenvalue pairs of A^-1
  /// nodes: roots of d^(s-1)/dx^(s-1) [x^(s-1) (x - 1)^s], c_s = 1 (HairerWanner1996, IV.5, (5.3))
  RadauVector c;
  /// Butcher matrix, a_ij = int_0^c_i l_j (collocation; HairerWanner1996, IV.5, (5.4)); b is its last row
  RadauMatrix A;
  RadauMatrix W;   ///< A^-1: stage derivatives h Y'_i = sum_j W_ij Z_j
  /// T^-1 W T = diag(gamma, [alpha_1 beta_1; -beta_1 alpha_1], ...): column 0 the real
  /// eigenvector, then the real and imaginary parts of the eigenvector of alpha_k + i beta_k
  /// (HairerWanner1996, IV.8, (8.15)-(8.16), for s stages).
  RadauMatrix T, Tinv;
  double gamma = 0.0;
  RadauVector alpha, beta;  ///< size pairs
  /// Embedded estimate of order s on the nodes 0, c_1..c_s: yhat_1 - y_1 = h y'_0 / gamma +
  /// sum_j d_j Z_j with d = W^T (bhat - b) (HairerWanner1996, IV.8, (8.17)-(8.18)).
  RadauVector d;
  /// Collocation polynomial u(t0 + x h) = y0 + sum_j L_j(x) Z_j, (L_1..L_s)(x) = P^T (x, .., x^s)
  /// (HairerWanner1996).
  RadauMatrix P;
  /// Where |x prod (x - c_i)| (the interpolation error factor) peaks on [0, 1].
  double xDense = 0.0;

  /// L(x) and L'(x) (derivative in x) of the collocation polynomial.
  RadauVector lagrange(double x) const;
  RadauVector lagrangeDerivative(double x) const;
  /// The Lagrange basis polynomial of the node 0 on the nodes 0, c_1..c_s:
  /// prod_i (x - c_i) / (0 - c_i).
  double lagrangeOfStart(double x) const;

  /// The method with `stages` = 3, 5 or 7 stages. @throws InputError otherwise.
  static const RadauCoefficients& get(int stages);
};

}  // namespace flexmbd
