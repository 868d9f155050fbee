// linearSpinStiffness (bodies/ffr_beam_model_3d.hpp): the beam's stiffening by its own
// spin, linearised for the SID (docs/fe-import.md, "SID").
#include <Eigen/SparseCholesky>

#include "bodies/ffr_beam_model_3d.hpp"

namespace flexmbd {

std::array<std::array<SpMat, 3>, 3> linearSpinStiffness(const FfrBeamModel3d& model) {
  std::array<std::array<SpMat, 3>, 3> G;
  if (!model.geometricStiffening()) return G;
  const FfrInvariants3d& inv = model.invariants();
  const Eigen::SimplicialLDLT<SpMat> K(inv.kff);  // positive definite under the reference conditions
  // int rho N_k^T u0_l dV = row k of positionShape[l]
  const auto P = [&](int k, int l) -> VecX { return inv.positionShape[l].row(k).transpose(); };
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) {
      // the coefficient of w_a w_b in f(w) = -sum_kl (w_k w_l - delta_kl |w|^2) P(k, l)
      VecX f = a == b ? VecX(P(0, 0) + P(1, 1) + P(2, 2) - P(a, a)) : VecX(-(P(a, b) + P(b, a)));
      const VecX q = K.solve(f);
      SpMat KG = 0.5 * (model.strainEnergyHessian(q) - model.strainEnergyHessian(-q));
      if (a != b) KG *= 0.5;  // the pair appears twice in sum_kl w_k w_l G_kl
      KG.prune(0.0, 0.0);
      G[a][b] = KG;
      G[b][a] = KG;
    }
  }
  return G;
}

}  // namespace flexmbd
