/// @file
/// The scene object of a flexible body imported from a finite element code ("type":
/// "fe_body", docs/scene-format.md "FE bodies"; docs/fe-import.md): which export to read
/// ("abaqus", "ansys" or "calculix" files, relative to the scene file's folder), and the reduction
/// options of FeBodyModel (modes, stiffness scale, modal damping, point masses).
#pragma once

#include <string>

#include "bodies/fe_body_model.hpp"
#include "scene/json_reader.hpp"

namespace flexmbd::scenereaders {

/// Key `key` of `r`: a file path, relative to `baseDir` (the scene file's folder) unless
/// absolute. @throws InputError naming the key if it is not a non-empty string.
std::string filePath(const jsonread::ObjectReader& r, const std::string& key, const std::string& baseDir);

/// The FE data of the body object `r` (exactly one of the keys "abaqus", "ansys",
/// "calculix"), each
/// file path relative to `baseDir` unless absolute.
/// @throws InputError naming the key, or the file and line (the readers).
FeBodyData readFeBodyFiles(const jsonread::ObjectReader& r, const std::string& baseDir);

/// The options of `r`: "modes", "stiffness_scale", "damping_ratio", "point_masses"
/// [{"node": FE node number, "mass": kg}, ...], "interfaces" [{"name", "kind": "rigid" |
/// "averaging", "nodes": [numbers] or "node_set": name, "point"}, ...] (nodes of `data`),
/// "reduction" ("free_free" or "craig_bampton") with "reference" (a rigid interface),
/// "inertia_modes", "spin_stiffening" {"calculix": {"job"}, "spin"} (the files relative to
/// `baseDir`).
/// @throws InputError naming the key, or the file and line.
FeBodyOptions readFeBodyOptions(const jsonread::ObjectReader& r, const FeBodyData& data, const std::string& baseDir);

/// Key "stresses" of `r`: {"calculix_frd": [paths]}, the FE code's results (displacement
/// and stress of modes or load cases) whose combinations give the stress shapes of the
/// model's coordinates (6 N x nf; bodies/fe_stress.hpp).
/// @throws InputError naming the key, a file, or the coordinate the results do not span.
MatX readFeStressShapes(const jsonread::ObjectReader& r, const FeBodyData& data, const FeBodyModel& model,
                        const std::string& baseDir, const std::string& owner);

}  // namespace flexmbd::scenereaders
