/// @file
/// Kinematics scene files: a planar linkage of rigid link elements, its inputs and the
/// settings of the kinematic analysis (Doc000), read strictly (unknown keys,
/// missing keys, wrong types, non-finite numbers are errors naming their location).
/// The format is documented in docs/kinematics.md.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "linkage/kinematic_analysis.hpp"
#include "linkage/linkage_2d.hpp"

namespace flexmbd {

/// A linkage ready to analyse. Linkage2d is referred to by KinematicAnalysis, so keep
/// the scene alive while analysing it.
/// Most steps of an analysis (scene "steps" and --steps): 1e7 rows of kinematics.csv are
/// about a GB, some 50 s CPU at 5 us per step.
constexpr long kMaxKinematicSteps = 10000000;

struct KinematicsScene {
  std::string name;
  Linkage2d linkage;  ///< finalized
  KinematicSettings settings;
};

/// Reads and parses a kinematics scene file. Error messages start with the file path.
/// @throws InputError on any invalid input (one line, with the location).
KinematicsScene loadKinematicsScene(const std::string& path);

/// Parses JSON text; `source` names the text in error messages.
KinematicsScene parseKinematicsSceneText(const std::string& text, const std::string& source = "<scene>");

/// Builds a kinematics scene from parsed JSON; the linkage is finalized at the end.
KinematicsScene parseKinematicsScene(const nlohmann::json& j);

}  // namespace flexmbd
