/// @file
/// Scene files: a JSON description of a model, its solver settings and extra outputs,
/// read strictly (unknown keys, missing keys, wrong types and out-of-range numbers are
/// errors that name their location). The format is documented in docs/scene-format.md.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "bodies/body_geometry.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd {

/// An extra quantity written to results.csv at every output time: one object of a
/// scene's "outputs" (parseOutputRequest). columnNames() names its columns and
/// evaluate() gives their values at a state (of an OutputSample, for example).
struct OutputRequest {
  /// The kind of quantity, the scene's "type" key.
  enum class Type {
    Point,   ///< world position and velocity of a body point
    Energy,  ///< kinetic, potential and total energy of the system
    Deflection,  ///< elastic displacement (body frame) and section forces at a beam point
    Stress,      ///< stress components and von Mises at a node of an fe_body with "stresses"
  };
  Type type = Type::Point;     ///< which quantity; the members below apply to the kinds they name
  std::string name;            ///< Point: prefix of the columns
  std::string bodyName;        ///< Point: the body the point belongs to
  BodyIndex body;              ///< Point: index of that body in the System
  Vec2 point = Vec2::Zero();   ///< Point, Deflection: body-frame coordinates of the point
  bool spatial = false;        ///< Point or Deflection in a spatial scene (point3)
  Vec3 point3 = Vec3::Zero();  ///< Point, Deflection (spatial): body-frame coordinates
  int pointId = Body::kAnyPoint;  ///< Point: the body's identifier of the point (Body::resolvePoint)
  int element = 0;             ///< Deflection: element of the beam mesh holding the point
  double xi = 0.0;             ///< Deflection: its local coordinate in [0, 1]
  int node = 0;                ///< Stress: the FE code's node number
  MatX stressShape;            ///< Stress: the node's 6 x nf stress shape, sigma = stressShape q_f

  /// Point: "<name>.x", "<name>.y", "<name>.vx", "<name>.vy";
  /// Deflection: "<name>.ux", "<name>.uy" (elastic displacement in the body frame),
  /// "<name>.N", "<name>.M" (axial force and bending moment of the beam there); spatial:
  /// "<name>.x", ".y", ".z", ".vx", ".vy", ".vz" and "<name>.ux", ".uy", ".uz", ".N", ".Qy",
  /// ".Qz", ".Mx", ".My", ".Mz" (section forces and moments in element axes);
  /// Energy: "energy.kinetic", "energy.potential", "energy.total";
  /// Stress: "<name>.sxx", ".syy", ".szz", ".sxy", ".syz", ".szx" (FE axes), ".von_mises".
  std::vector<std::string> columnNames() const;
  /// Values matching columnNames() at global coordinates q and velocities v (size nq).
  /// Point: r and Jr v_body from Body::pointKinematics; Energy: kineticEnergy,
  /// potentialEnergy and their sum.
  /// @pre sys is finalized and q, v have numCoordinates() entries.
  std::vector<double> evaluate(const System& sys, const VecX& q, const VecX& v) const;
};

/// A model ready to run, planar or spatial ("dimension": 3), as loadScene() reads it
/// from a scene file: run it with simulate(scene.system, scene.solver, ...) and evaluate
/// `outputs` at each OutputSample. System is move-only, so a Scene is too.
/// The scene's "sensitivity" object (docs/scene-format.md, docs/sensitivities.md): what
/// a run computes besides its results where the command line (or Python's run) names
/// nothing itself.
struct SensitivityRequest {
  std::vector<std::string> parameters;  ///< dotted scene paths (forward or adjoint)
  std::vector<std::string> adjoint;     ///< adjoint outputs KIND:COLUMN (need parameters)
  bool errorControl = true;             ///< the forward sensitivities in the error test
};

struct Scene {
  std::string name;       ///< the scene's "name" (results' summary.json)
  System system;          ///< the model, finalized
  SolverSettings solver;  ///< the scene's "solver" object (defaults for the keys it omits)
  std::vector<OutputRequest> outputs;  ///< the scene's "outputs", in order
  std::vector<BodyGeometry> geometry;  ///< the rigid bodies' "geometry" (viewing only)
  std::vector<FeBodyDrawing> feBodies;  ///< the fe_bodies' surfaces and stress shapes
  SensitivityRequest sensitivity;       ///< the scene's "sensitivity" (none: empty lists)
};

/// Reads and parses a scene file. Error messages start with the file path.
/// @throws InputError if the file cannot be read, is not valid JSON (the message gives
///         nlohmann's byte position), or does not describe a valid scene.
Scene loadScene(const std::string& path);

/// Parses JSON text; `source` names the text in error messages (a file path; the files
/// the scene names are relative to its folder).
/// A number too large for a double (1e999) is an InputError naming its location.
Scene parseSceneText(const std::string& text, const std::string& source = "<scene>");

/// Builds a scene from parsed JSON; the System is finalized at the end. Files the scene
/// names (an fe_body's exports) are relative to `baseDir` ("": the working directory).
/// @throws InputError (one line, starting with the location, e.g.
///         `bodies[1] ("rod"): key "mass" must be > 0, got -1`) on any invalid input.
Scene parseScene(const nlohmann::json& j, const std::string& baseDir = "");

/// One output object of the scene format ("point", "deflection", "energy", "stress"; the
/// keys of docs/scene-format.md, "Outputs") for `sys` (finalized or not); `earlier`: the
/// outputs already requested (names must differ); `spatial`: a "dimension": 3 model;
/// `feBodies`: the fe_bodies' drawings (a stress output needs its body's stress shapes).
/// @throws InputError starting with `where`.
OutputRequest parseOutputRequest(const nlohmann::json& j, const std::string& where, const System& sys,
                                 const std::vector<OutputRequest>& earlier, bool spatial,
                                 const std::vector<FeBodyDrawing>& feBodies = {});

/// Range checks of solver settings with the scene's key names (rtol > 0, t_end >
/// t_start, ...), then SolverSettings::validate(). Used after command-line overrides.
/// @throws InputError starting with "solver: ".
void checkSolverSettings(const SolverSettings& s);

}  // namespace flexmbd
