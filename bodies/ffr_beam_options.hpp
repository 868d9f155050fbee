/// @file
/// The options of a beam model (FfrBeamModelT, bodies/ffr_beam_model.hpp), one definition
/// for planar (Dim 2) and spatial (Dim 3) bodies: reference conditions (B2), modal
/// reduction, inertia modes, geometric stiffening, beam theory.
#pragma once

#include <vector>

#include "bodies/modal_reduction.hpp"
#include "elements/beam_section.hpp"

namespace flexmbd {

/// Reference conditions (Doc003, B2): what fixes the body frame in the body, as
/// conditions on the nodal coordinates (3 in the plane, 6 in space).
template <int Dim>
struct ReferenceConditionsT {
  enum class Type {
    /// Chord frame. Plane: node A fixed in the frame, node B on the chord A-B (the
    /// frame's x axis). Space: node A's three translations zero, node B's two
    /// translations transverse to the body x axis zero, the twist at A zero; node B must
    /// lie on the body x axis through A (the mesh puts the chord along x).
    PinnedPinned,
    /// Node A fixed in the frame, its cross-section rotation(s) zero (tangent frame).
    Clamped,
    /// Mean axes (Tisserand / Buckens): int rho u_f dV = 0 and int rho u0 x u_f dV = 0,
    /// exactly on the nodal coordinates (the mean-axis conditions: Shabana2005, ch. 5).
    FreeFree,
  };
  /// Default: pinned-pinned in the plane, clamped in space.
  Type type = Dim == 2 ? Type::PinnedPinned : Type::Clamped;
  int nodeA = 0;
  int nodeB = -1;  ///< pinned-pinned only; -1: the last node
};

using ReferenceConditions = ReferenceConditionsT<2>;
using ReferenceConditions3d = ReferenceConditionsT<3>;

template <int Dim>
struct FfrBeamOptionsT {
  ReferenceConditionsT<Dim> reference;
  /// Modal reduction: 0 keeps every nodal coordinate; n > 0 keeps the first n modes
  /// (under the reference conditions, mass-normalised); `modeSet` (1-based) keeps a
  /// chosen set instead. Craig-Bampton: the fixed-interface modes (0: Guyan).
  int modes = 0;
  std::vector<int> modeSet;
  /// Normal modes, or Craig-Bampton (ModalReduction, bodies/modal_reduction.hpp): one
  /// static constraint mode per coordinate of the `interfaceNodes` (3 or 6 per node) not
  /// already held by the reference conditions, then the fixed-interface modes.
  ModalReduction reduction = ModalReduction::Normal;
  /// Craig-Bampton only (required there): the interface nodes, e.g. the joints' nodes.
  std::vector<int> interfaceNodes;
  /// With a reduction: add the static responses to the inertia loads of the frame's rigid
  /// motion, so that the quasi-static deformation by the body's own inertia is held
  /// exactly (withStaticModes, bodies/modal_reduction.hpp). Plane: translation S-bar^T,
  /// centrifugal I1, angular acceleration J0 (at most 4). Space: translation S-bar^T and
  /// int rho N^T u0_k of every linear field W u0 of the rotation's accelerations
  /// alpha x u0 + omega x (omega x u0) (at most 12).
  bool inertiaModes = false;
  /// Element-averaged second-order membrane strain in the strain energy (stiffening by
  /// axial load, locking-free); off: the linear FFR model (docs/flexible-bodies.md).
  bool geometricStiffening = false;
  /// The elements' beam theory (BeamTheory): Rayleigh adds the sections' rotary inertia
  /// of bending (and, in space, its second-order rotation, R_kl and H_i). Planar bodies:
  /// Euler-Bernoulli only so far (Rayleigh is an InputError).
  BeamTheory theory = BeamTheory::EulerBernoulli;
};

using FfrBeamOptions = FfrBeamOptionsT<2>;
using FfrBeamOptions3d = FfrBeamOptionsT<3>;

}  // namespace flexmbd
