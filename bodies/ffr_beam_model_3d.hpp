// The spatial beam model FfrBeamModel3d is FfrBeamModelT<SpatialBeam>, the one beam-model
// code for planar and spatial bodies: bodies/ffr_beam_model.hpp (BeamMesh3d:
// bodies/beam_mesh.hpp; FfrBeamOptions3d: bodies/ffr_beam_options.hpp).
#pragma once

#include "bodies/ffr_beam_model.hpp"
