/// @file
/// Tensegrity scene files: JSON with top-level "model": "tensegrity", read strictly
/// (unknown keys, missing keys, wrong types and out-of-range numbers are errors naming
/// their location). Format: docs/tensegrity.md.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "tensegrity/massless_cable_integrator.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "tensegrity/tensegrity_time_stepper.hpp"

namespace flexmbd {

struct TensegrityScene {
  std::string name;
  std::unique_ptr<TensegrityStructure> structure;  ///< finalized (and prestressed if asked)
  enum class Method { TimeStepping, MasslessCables } method = Method::TimeStepping;
  TimeSteppingSettings timeStepping;   ///< method 1 ("time_stepping")
  MasslessCableSettings massless;      ///< method 2 ("massless_cables")
};

/// True if the file is a JSON object whose "model" is "tensegrity" (false if it cannot
/// be read or parsed: the ordinary scene reader then reports the error).
bool isTensegritySceneFile(const std::string& path);

/// @throws InputError (one line, starting with the file and the location).
TensegrityScene loadTensegrityScene(const std::string& path);
TensegrityScene parseTensegrityScene(const nlohmann::json& j);
/// @throws InputError "solver: key "t_end" must ..." if t_end - t_start is not a span the
/// integrators can resolve (resolvableTimeSpan; --t-end is checked again after it is applied).
void checkTensegrityTimes(const TensegrityScene& scene);

}  // namespace flexmbd
