/// @file
/// What the planar (scene/scene.cpp) and spatial (scene/spatial_scene.cpp) scene readers share
/// for flexible bodies (docs/scene-format.md): the body's type and name, the mesh ("beam"
/// or "nodes" and "elements"), the beam-model keys ("reference", "modes", "reduction" with
/// "interface_nodes", "inertia_modes", "geometric_stiffening", "beam_theory"; each
/// reader's key list says which a body accepts), the initial elastic state and the sized
/// matrices of "flexible_invariants" bodies.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bodies/beam_mesh.hpp"
#include "scene/json_reader.hpp"

namespace flexmbd::scenereaders {

/// The "type" (one of rigid, flexible, flexible_invariants, fe_body) and "name" of a body object,
/// the name "ground" refused (reserved for the fixed ground body).
std::pair<std::string, std::string> readBodyTypeAndName(jsonread::ObjectReader& r);

/// The mesh of a flexible body, every element with the section (and, spatial, the y axis
/// hint) of `element`: key "beam" {"length", "elements", "origin"} (a straight beam along
/// the body x axis; `beamKeys` its allowed keys) or keys "nodes" [[x, y(, z)], ...] and
/// "elements" [[i, j], ...]. BeamMesh2d or BeamMesh3d.
/// @throws InputError naming the key.
template <class Mesh>
Mesh readBeamMesh(const jsonread::ObjectReader& r, const typename Mesh::Element& element,
                  const std::vector<std::string>& beamKeys, const std::string& beamContext);

/// Fills options.reference, .modes / .modeSet, .reduction / .interfaceNodes,
/// .inertiaModes, .geometricStiffening and .theory from the body object `r` (a mesh of
/// `numNodes` nodes); FfrBeamOptions or FfrBeamOptions3d.
/// @throws InputError naming the key.
template <class Options>
void readBeamModelOptions(const jsonread::ObjectReader& r, int numNodes, Options& options);

/// Key `key` ("elastic_coordinates", "elastic_velocities") as `n` numbers, one per
/// elastic coordinate of the body, or zeros if absent.
VecX readElasticState(const jsonread::ObjectReader& r, const char* key, int n);

/// Key `key` of an invariants object as a rows x cols matrix (`nf` elastic coordinates,
/// from m_ff, named in the message).
MatX readSizedMatrix(const jsonread::ObjectReader& iv, const char* key, int rows, int cols, int nf);
/// The same for a matrix `m` already read from key `key` (e.g. a vector).
MatX sizedMatrix(const jsonread::ObjectReader& iv, const char* key, const MatX& m, int rows, int cols, int nf);
/// An nf x nf invariant as a sparse matrix (exact zeros dropped); `optional`: zero if absent.
SpMat readSquareInvariant(const jsonread::ObjectReader& iv, const char* key, int nf, bool optional = false);

}  // namespace flexmbd::scenereaders
