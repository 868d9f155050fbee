/// @file
/// The DAE F(t, y, y') = 0 that the integrator sees, its residual and its Jacobian
/// dF/dy + cj dF/dy', assembled from the components of a finalized System.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/dae_problem.hpp"
#include "core/sparse_pattern.hpp"
#include "core/system.hpp"

namespace flexmbd {

/// How the constrained equations of motion are posed (see docs/formulations.md).
enum class Formulation {
  Ggl,     ///< stabilised index 2 (GearGuptaLeimkuhler1985): y = [q, v, lambda, mu]
  Index3,  ///< position constraints: y = [q, v, lambda]
  Index1,  ///< acceleration constraints: y = [q, v, lambda]; drift not corrected
};
std::string toString(Formulation f);
/// "ggl", "index3", "index1". @throws InputError otherwise.
Formulation parseFormulation(const std::string& name);

/// Where each class of unknowns starts in y (and each class of equations in F).
struct DaeLayout {
  int nq = 0;       ///< coordinates
  int nv = 0;       ///< velocities (= nq when every body has q' = v)
  int m = 0;        ///< constraint equations
  int q = 0;        ///< offset of positions
  int v = 0;        ///< offset of velocities
  int lambda = 0;   ///< offset of multipliers
  int mu = -1;      ///< offset of stabilising multipliers (GGL only)
  int size = 0;
};

/// Weight of the elastic coordinates in the GGL stabilisation metric D (frame
/// coordinates: 1). The position-level correction D G^T mu goes into the frame
/// coordinates, not into lightly damped elastic modes that would carry it to the end of
/// the run; a small positive weight keeps G D G^T regular where the frame coordinates
/// alone cannot satisfy a constraint. Derivation and measurements: docs/formulations.md.
inline constexpr double kElasticStabilisationWeight = 1e-6;
/// D = 1 on frame coordinates, kElasticStabilisationWeight on elastic ones.
VecX defaultStabilisationMetric(const System& sys);

/// GGL residual (STYLE.md; GearGuptaLeimkuhler1985), with q' = T(q) v (docs/spatial.md):
///   F_q  = q' - T(q) (v - D G^T mu),  F_v = M v' - Q + G^T lambda,  F_g = g(q, t),
///   F_gv = G v + g_t,
/// G the velocity Jacobian (m x nv). Index 3 drops mu and F_gv; index 1 replaces F_g by
/// G v' + (G v)_q T v + g_tt. With T = I (planar models), F_q = q' - v + D G^T mu.
/// Which components' terms a residual evaluation takes (DaeSystem::residualOfParts): one
/// flag per body, force and constraint of the system.
struct ResidualParts {
  std::vector<char> bodies, forces, constraints;
  static ResidualParts none(const System& sys);
};

class DaeSystem final : public DaeProblem {
 public:
  /// @throws InputError if the system is not finalized.
  DaeSystem(const System& sys, Formulation formulation);
  /// GGL with the stabilisation metric D (diagonal, nv, positive): F_q = q' - T (v - D G^T mu)
  /// (GearGuptaLeimkuhler1985).
  /// The first constructor takes defaultStabilisationMetric(sys).
  DaeSystem(const System& sys, Formulation formulation, VecX stabilisationMetric);
  /// With the constraint equations `released` (ascending; redundant constraints resolved,
  /// docs/formulations.md): each one's rows F_g (and F_gv of GGL) become lambda_k = 0
  /// (and mu_k = 0); the size and the other rows are unchanged.
  /// @throws InputError if a released index is out of range or not ascending.
  DaeSystem(const System& sys, Formulation formulation, VecX stabilisationMetric, std::vector<int> released);
  const VecX& stabilisationMetric() const { return metric_; }
  /// The released constraint equations (ascending; empty: none).
  const std::vector<int>& releasedEquations() const { return released_; }

  const System& system() const { return sys_; }
  Formulation formulation() const { return formulation_; }
  const DaeLayout& layout() const { return layout_; }
  /// Pattern of dF/dy + cj dF/dy', fixed for the whole run.
  int size() const override { return layout_.size; }
  const SparsePattern& pattern() const override { return pattern_; }
  /// 1 for differential, 0 for variables excluded from the error test (multipliers;
  /// for index 3 also the velocities, which are index-2 variables there).
  VecX differentialIds() const override;

  /// Working memory of one integrator: per body, constraint and force (sized from the
  /// model; evaluations with it allocate nothing after the first).
  std::unique_ptr<DaeScratch> makeScratch() const override;
  using DaeProblem::jacobian;
  using DaeProblem::residual;
  void residual(double t, const double* y, const double* yp, double* F, DaeScratch& scratch) const override;
  void jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                DaeScratch& scratch) const override;

  /// The residual with only the terms of the components in `parts`: a left-out body adds
  /// no mass, internal or gravity terms to F_v, a left-out force nothing, a left-out
  /// constraint neither its rows (zero) nor its G^T lambda, D G^T mu terms; the terms of no
  /// component (q' - T v, released rows) stay. The difference of two systems that differ
  /// only in the components in `parts` is thus their full residuals' difference (ResidualDifferences).
  /// Allocates nothing. @throws std::logic_error if `parts` does not fit the system.
  void residualOfParts(double t, const double* y, const double* yp, double* F, const ResidualParts& parts,
                       DaeScratch& scratch) const;

  /// dF/dy' of the GGL and index-3 forms is I on the q rows and M(q) on the v rows (the
  /// constraint rows hold no rates): the product costs one mass-matrix product per body.
  /// Index 1 (G on the multiplier rows) is not provided.
  bool providesRateJacobianProduct() const override { return formulation_ != Formulation::Index1; }
  void addRateJacobianProduct(double t, const double* y, const double* yp, const double* x, double* r,
                              DaeScratch& scratch) const override;

  /// Elimination groups for a fill-reducing ordering of the Jacobian (size of y): 0 for
  /// the positions and velocities of elastic coordinates, 1 for frame coordinates
  /// (coupled to their whole body), 2 for multipliers (zero diagonal); KluOrdering
  /// (integrators/klu_ordering.hpp) chooses which go last.
  std::vector<int64_t> eliminationGroups() const override;

  /// y and y' from positions, velocities, accelerations and multipliers (mu = 0).
  void packState(const VecX& q, const VecX& v, const VecX& a, const VecX& lambda, VecX& y,
                 VecX& yp) const;

 private:
  // One source for both: instantiated with IdentityT = true for models whose velocities are
  // all coordinate rates (planar), where the T(q) terms compile away, and false otherwise.
  template <bool IdentityT>
  void residualImpl(double t, const double* y, const double* yp, double* F, DaeScratch& scratch,
                    const ResidualParts* parts) const;
  template <bool IdentityT>
  void jacobianImpl(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                    DaeScratch& scratch) const;
  const System& sys_;
  Formulation formulation_;
  DaeLayout layout_;
  SparsePattern pattern_;
  VecX metric_;  ///< D of the GGL stabilisation (nv)
  std::vector<int> released_;  ///< released constraint equations, ascending
  /// Per constraint with released equations: its kept local rows (ascending); empty
  /// vector and partial_ false for a constraint with none released.
  std::vector<std::vector<int>> keptRows_;
  std::vector<char> partial_;
  /// Per body with T != I: the structural non-zeros of T (nq x nv) and T+ (nv x nq), each in
  /// a square pattern of size nq (empty for T = I). Built once: a body's T is sparse (the
  /// identity on elastic coordinates), and assembling it densely made the Jacobian pattern
  /// of a spatial flexible body quadratic in its mesh.
  std::vector<SparsePattern> ratePattern_, rateInversePattern_;
};

}  // namespace flexmbd
