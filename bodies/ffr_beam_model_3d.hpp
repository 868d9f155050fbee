/// @file
/// The spatial beam model FfrBeamModel3d is FfrBeamModelT<SpatialBeam>, the one beam-model
/// code for planar and spatial bodies: bodies/ffr_beam_model.hpp (BeamMesh3d:
/// bodies/beam_mesh.hpp; FfrBeamOptions3d: bodies/ffr_beam_options.hpp).
#pragma once

#include "bodies/ffr_beam_model.hpp"

namespace flexmbd {

/// The spin stiffness G_kl (FfrInvariants3d::spinStiffness) of a beam model with geometric
/// stiffening, linearised about the undeformed beam: per unit w_k w_l the static response
/// q = K_ff^-1 f_kl to the centrifugal load of the frame's spin (f(w) = -sum_kl Om_kl
/// int rho N_k^T u0_l dV, Om = w~ w~) and the geometric stiffness of that state, the
/// part of the strain energy's Hessian linear in q: K_G(q) = (H(q) - H(-q)) / 2 (exact for
/// the quartic strain energy of the element-averaged membrane strain). What a SID holds of
/// the beam's stiffening (flexmbd sid). A reduced model's basis must hold the axial
/// stretch (inertia modes), else its static response has none and G is about zero.
/// Without geometric stiffening: all empty.
std::array<std::array<SpMat, 3>, 3> linearSpinStiffness(const FfrBeamModel3d& model);

}  // namespace flexmbd
