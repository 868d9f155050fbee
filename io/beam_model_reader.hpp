// Reader of the beam-model keys that planar and spatial flexible bodies share
// (docs/scene-format.md): "reference" (conditions B2), "modes" (modal reduction),
// "reduction" with "interface_nodes" (Craig-Bampton), "inertia_modes",
// "geometric_stiffening" and, for spatial bodies, "beam_theory". Called by io/scene.cpp and io/spatial_scene.cpp (whose key
// lists say which of these a body accepts).
#pragma once

#include "io/json_reader.hpp"

namespace flexmbd::scenereaders {

/// Fills options.reference, .modes / .modeSet, .reduction / .interfaceNodes,
/// .inertiaModes, .geometricStiffening (and, spatial, .theory) from the body
/// object `r` (a mesh of `numNodes` nodes); FfrBeamOptions or FfrBeamOptions3d.
/// @throws InputError naming the key.
template <class Options>
void readBeamModelOptions(const jsonread::ObjectReader& r, int numNodes, Options& options);

}  // namespace flexmbd::scenereaders
