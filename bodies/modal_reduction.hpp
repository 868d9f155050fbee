/// @file
/// Reduction bases shared by the planar and spatial beam models (FfrBeamModel,
/// FfrBeamModel3d), both given the body's stiffness K and mass M in its elastic
/// coordinates after the reference conditions (q_n = B2 x):
///  - normal modes of K phi = omega^2 M phi (GeradinRixen);
///  - Craig-Bampton (CraigBampton1968): static constraint modes (unit displacement of each interface
///    coordinate, the rest statically condensed) and fixed-interface normal modes (the
///    interface held). docs/flexible-bodies.md, "Craig-Bampton reduction";
///  - static modes appended to either basis (the inertia modes: static responses to the
///    inertia loads of the frame's rigid motion), docs/flexible-bodies.md, "Section
///    forces of reduced bodies".
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// How the elastic coordinates are reduced (FfrBeamOptions, FfrBeamOptions3d;
/// docs/flexible-bodies.md).
enum class ModalReduction {
  /// Normal modes under the reference conditions (`modes` / `modeSet`; none: nodal).
  Normal,
  /// Craig-Bampton: one static constraint mode per interface coordinate (every nodal
  /// coordinate of the `interfaceNodes` not already held by the reference conditions),
  /// then `modes` (or `modeSet`) fixed-interface normal modes (0: static condensation
  /// only, Guyan).
  CraigBampton,
};

/// The 1-based mode numbers to keep: `set` if it is not empty, else 1..count (none for
/// count 0).
/// @throws InputError naming `owner`: count < 0, a number < 1, a number chosen twice.
std::vector<int> chosenModes(int count, const std::vector<int>& set, const std::string& owner);

/// The sign convention of every mode basis the engine computes: each column's largest
/// entry in magnitude (the first of those within 1e-6 of it) made positive. Eigensolvers
/// leave the sign open; fixed, a scene read twice, or with a parameter moved a step
/// (design sensitivities, docs/sensitivities.md), gives modal coordinates of the same shapes.
void fixModeSigns(MatX& phi);

/// The mass-normalised eigenvectors (columns, phi^T M phi = I) of K phi = omega^2 M phi (GeradinRixen)
/// numbered `keep` (1-based, ascending frequency); `omega` (if given) receives their
/// natural frequencies (rad/s). K symmetric, M symmetric positive definite (dense).
/// @throws InputError naming `owner` if a chosen mode does not exist (`what`: "mode" or
/// "fixed-interface mode", named in the message with the modes available).
MatX normalModes(const MatX& K, const MatX& M, const std::vector<int>& keep, const std::string& owner,
                 VecX* omega = nullptr, const std::string& what = "mode");

/// The free-free normal modes of a body whose stiffness K (n x n, symmetric positive
/// semi-definite) vanishes on the rigid motions `rigid` (n x 6: three translations, three
/// rotations), mass M symmetric (not necessarily positive definite: solid element masses
/// as stored may not be, docs/fe-import.md): the first `count` elastic modes, the six
/// rigid-body eigenvalues (|lambda| <= 1e-6 lambda_7, else InputError) dropped.
/// Shift-invert with a C-inner product, C = K - sigma M positive definite (sigma < 0):
/// M phi = nu C phi, nu = 1 / (lambda - sigma), the largest nu by Spectra's Lanczos
/// (SymGEigsSolver, Cholesky mode). The modes are made exactly M-orthogonal to `rigid`
/// (mean axes: the deformation carries no linear and, to first order, no angular momentum
/// relative to the frame) and mass-normalised. `omega` receives their frequencies (rad/s),
/// `rigidEigenvalues` (if given) the six dropped eigenvalues (rad^2/s^2).
/// @throws InputError naming `owner`: count < 1 or count + 6 >= n, C not positive definite,
/// the solver not converging, not exactly six near-zero eigenvalues.
MatX freeFreeModes(const SpMat& K, const SpMat& M, const MatX& rigid, int count, const std::string& owner,
                   VecX* omega = nullptr, VecX* rigidEigenvalues = nullptr);

/// The clamped normal modes of a body of stiffness K and mass M (n x n, symmetric; M not
/// necessarily positive definite, as freeFreeModes) with the DOF `held` (0-based rows)
/// removed: K_ff phi = lambda M_ff phi over the other DOF, the lowest `count` with lambda
/// > 0. K_ff is positive definite when the held DOF stop every rigid motion, so the shift
/// is sigma = 0: M_ff phi = nu K_ff phi, nu = 1 / lambda, the largest nu by the Lanczos of
/// freeFreeModes (M never factored; the negative-mass modes of an indefinite M have nu < 0
/// and are not among them). Returns n x count, zero at the held DOF, mass-normalised
/// (phi^T M phi = I); `omega` receives the frequencies (rad/s), ascending.
/// @throws InputError naming `owner`: a held DOF out of range or given twice, count < 1 or
/// count >= the free DOF, K_ff not positive definite (a rigid motion left free), the
/// solver not converging, fewer than `count` modes of positive mass.
MatX clampedModes(const SpMat& K, const SpMat& M, const std::vector<int>& held, int count, const std::string& owner,
                  VecX* omega = nullptr);

/// The interface conditions G x of a body whose nodal coordinates (`nodeDofs` per node,
/// node k's at nodeDofs k .. nodeDofs k + nodeDofs - 1) are q_n = B2 x: the rows of B2
/// of every coordinate of the `nodes` (node order, then coordinate order). `dofs`
/// receives the nodal coordinate of each row.
/// @throws InputError naming `owner`: no nodes, a node out of range or listed twice.
MatX interfaceConditions(const SpMat& B2, int nodeDofs, const std::vector<int>& nodes, const std::string& owner,
                         std::vector<int>& dofs);

/// A Craig-Bampton basis x = [Psi Phi] (eta_c, eta_m) in the coordinates x of K and M (CraigBampton1968).
struct CraigBamptonBasis {
  /// n x (nc + nm): the nc constraint modes, then the nm fixed-interface modes.
  MatX basis;
  /// The rows of G that are interface coordinates (one constraint mode each, the same
  /// order): G's rows without those that depend on earlier ones (zero rows: coordinates
  /// that the reference conditions already hold).
  std::vector<int> interfaceRows;
  /// Natural frequencies (rad/s) of the kept fixed-interface modes, in `keep` order.
  VecX fixedInterfaceFrequencies;
};

/// Craig-Bampton reduction (CraigBampton1968; GeradinRixen, the chapter on substructuring /
/// component mode synthesis)
/// of the structure with
/// stiffness K (symmetric positive definite: the reference conditions hold the body)
/// and mass M, interface coordinates G x (G r x n):
///   constraint modes  Psi = K^-1 G_i^T (G_i K^-1 G_i^T)^-1: G_i Psi = I, and K Psi =
///                     G_i^T Lambda loads only the interface (static condensation);
///   fixed-interface   Phi = Z phi, Z a basis of null(G_i), (Z^T K Z) phi =
///   modes             omega^2 (Z^T M Z) phi, mass-normalised, numbered `keep`;
/// G_i the independent rows of G (see interfaceRows). With G made of unit rows this is
/// the classical partition [I 0; -K_ii^-1 K_ib  Phi_i].
/// @throws InputError naming `owner`: a chosen fixed-interface mode that does not exist.
CraigBamptonBasis craigBamptonBasis(const SpMat& K, const SpMat& M, const MatX& G, const std::vector<int>& keep,
                                    const std::string& owner);

/// The basis (columns) extended by the static responses K^-1 F to the load vectors F
/// (columns), less what it already holds: modal truncation augmentation
/// (DickensNakagawaWittbrodt1997). Y = K^-1 F is made K-orthogonal
/// to the basis, then K-orthogonalised within itself (eigenvectors of Y^T K Y); parts
/// with a strain energy below 1e-12 of the largest static response's are dropped
/// (already held, or a zero load); the new columns are mass-normalised.
MatX withStaticModes(const SpMat& K, const SpMat& M, const MatX& basis, const MatX& F);

/// withStaticModes given the static responses Y (K Y = F) themselves: for a free body,
/// whose K is singular (freeStaticResponses), or a clamped one solved on its free DOF.
MatX withStaticResponses(const SpMat& K, const SpMat& M, const MatX& basis, MatX Y);

/// The static responses of a free body (K R = 0 on its rigid motions R, n x 6) to the
/// loads F with inertia relief: the part of F that accelerates the body rigidly removed,
/// F' = F - M R (R^T M R)^-1 R^T F, and K y = F' solved with R^T M y = 0 (mean axes) as the
/// saddle-point system [K  M R; R^T M  0] (y, lambda) = (F', 0) (sparse LU; lambda = 0
/// since R^T F' = 0). GeradinRixen, the section on inertia relief and the pseudo-inverse of
/// a floating structure.
/// @throws InputError naming `owner` if the system is singular (a mechanism besides the
/// six rigid motions).
MatX freeStaticResponses(const SpMat& K, const SpMat& M, const MatX& R, const MatX& F, const std::string& owner);

}  // namespace flexmbd
