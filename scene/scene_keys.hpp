/// @file
/// The keys every scene reader accepts, per kind of object: the one list that the
/// readers (scene/scene.cpp, scene/json_reader.cpp, linkage/kinematics_scene.cpp,
/// tensegrity/tensegrity_scene.cpp) pass to ObjectReader::allowOnly, and that
/// tests/test_docs_keys.cpp compares, both ways, with the key tables of
/// docs/scene-format.md (a table tagged `<!-- keys: ID ... -->` documents the keys of
/// the objects ID; an object's keys are the union of the tables tagged with it).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace flexmbd::scenekeys {

using Keys = std::vector<std::string>;

// ----- multibody scenes (flexmbd run) ------------------------------------------------
inline const Keys kScene = {"name",   "dimension", "gravity", "bodies", "joints",
                            "drivers", "forces",   "outputs", "solver", "sensitivity"};
inline const Keys kSensitivity = {"parameters", "adjoint", "error_control"};
inline const Keys kRigidBody = {"name",  "type",     "mass", "inertia", "com", "position",
                                "angle", "velocity", "angular_velocity", "geometry"};
inline const Keys kFlexibleBody = {"name",     "type",     "position",    "angle",
                                   "velocity", "angular_velocity",       "section",
                                   "beam",     "nodes",    "elements",   "reference",
                                   "modes",    "geometric_stiffening",   "elastic_coordinates",
                                   "elastic_velocities", "reduction", "interface_nodes", "inertia_modes",
                                   "beam_theory"};
inline const Keys kInvariantsBody = {"name",     "type",       "position",           "angle",
                                     "velocity", "angular_velocity", "invariants", "elastic_coordinates",
                                     "elastic_velocities"};
inline const Keys kSection = {"area",    "inertia", "width",         "height",      "youngs_modulus",
                              "density", "damping", "shear_modulus", "shear_factor"};
inline const Keys kBeam = {"length", "elements", "origin"};
inline const Keys kReferencePinnedPinned = {"type", "nodes"};
inline const Keys kReferenceClamped = {"type", "node"};
inline const Keys kReferenceFreeFree = {"type"};
inline const Keys kInvariants = {"mass", "first_moment", "polar_moment", "s_bar", "i1",    "j0",
                                 "m_ff", "s_tilde",      "k_ff",         "d_ff",  "points", "r"};
inline const Keys kInvariantsPoint = {"position", "shape", "rotation_shape"};
inline const Keys kJoint = {"name", "type", "bodies", "points"};  ///< revolute, fixed
inline const Keys kPrismaticJoint = {"name", "type", "bodies", "points", "axis"};
inline const Keys kBodyDriver = {"name", "type", "body", "law"};    ///< body_angle, body_x, body_y
inline const Keys kJointDriver = {"name", "type", "joint", "law"};  ///< joint_angle, joint_displacement
inline const Keys kLawConstant = {"type", "value"};
inline const Keys kLawConstantSpeed = {"type", "speed", "initial"};
inline const Keys kLawPolynomial = {"type", "coefficients"};
inline const Keys kLawHarmonic = {"type", "amplitude", "omega", "phase", "offset"};
inline const Keys kLawSpinUp = {"type", "speed", "ramp_time", "initial"};
inline const Keys kLawTabulated = {"type", "times", "values"};
inline const Keys kSpringDamper = {"name", "type", "bodies", "points", "stiffness", "damping", "free_length"};
inline const Keys kRotationalSpringDamper = {"name", "type", "joint", "stiffness", "damping", "free_angle"};
inline const Keys kAppliedLoad = {"name", "type", "body", "point", "force_x", "force_y", "torque"};
inline const Keys kEnergyOutput = {"type"};
inline const Keys kPointOutput = {"type", "name", "body", "point"};  ///< point, deflection
inline const Keys kStressOutput = {"type", "name", "body", "node"};
inline const Keys kSolver = {"formulation", "integrator", "rtol",        "atol",       "atol_angle",
                             "atol_elastic", "atol_velocity", "t_start",  "t_end",      "output_step",
                             "max_step",     "min_step",      "max_steps", "max_total_steps", "max_order", "initial_step",
                             "linear_solver", "fd_jacobian", "cross_singular", "elastic_start",
                             "quasi_static_above", "redundant_constraints"};

// spatial scenes ("dimension": 3)
inline const Keys kRigidBody3d = {"name",        "type",     "mass",             "inertia", "shape", "position",
                                  "orientation", "velocity", "angular_velocity", "geometry"};
inline const Keys kShapeBox = {"type", "size", "mass", "density", "offset", "orientation"};
inline const Keys kShapeSphere = {"type", "radius", "mass", "density", "offset", "orientation"};
inline const Keys kShapeCylinder = {"type", "radius", "length", "axis", "mass", "density", "offset", "orientation"};
inline const Keys kShapeTube = {"type",   "inner_radius", "outer_radius", "length", "axis",
                                "mass",   "density",      "offset",       "orientation"};
// "geometry" of a rigid body (viewing only): the shapes' keys without mass and density
inline const Keys kGeometryBox = {"type", "size", "offset", "orientation"};
inline const Keys kGeometrySphere = {"type", "radius", "offset", "orientation"};
inline const Keys kGeometryCylinder = {"type", "radius", "length", "axis", "offset", "orientation"};
inline const Keys kGeometryTube = {"type", "inner_radius", "outer_radius", "length", "axis", "offset", "orientation"};
inline const Keys kFlexibleBody3d = {"name",     "type",      "position",    "orientation", "velocity",
                                     "angular_velocity",     "section",     "beam",        "nodes",
                                     "elements", "y_axis",    "reference",   "modes",       "geometric_stiffening",
                                     "elastic_coordinates",  "elastic_velocities", "reduction", "interface_nodes",
                                     "inertia_modes", "beam_theory"};
inline const Keys kSection3d = {"area",          "inertia_y",     "inertia_z", "torsion_constant", "width",  "height",
                                "youngs_modulus", "shear_modulus", "poisson_ratio", "density",     "damping",
                                "shear_factor_y", "shear_factor_z"};
inline const Keys kBeam3d = {"length", "elements", "origin"};
inline const Keys kInvariantsBody3d = {"name",        "type",       "position",            "orientation",
                                       "velocity",    "angular_velocity", "invariants",    "elastic_coordinates",
                                       "elastic_velocities"};
inline const Keys kInvariants3d = {"mass",  "first_moment", "second_moment", "s_bar", "position_shape_x",
                                   "position_shape_y", "position_shape_z", "s_xx", "s_xy", "s_xz",
                                   "s_yy",  "s_yz",         "s_zz",          "m_ff",  "k_ff",
                                   "d_ff",  "points",       "r_xx",          "r_xy",  "r_xz",
                                   "r_yy",  "r_yz",         "r_zz",          "h_x",   "h_y",
                                   "h_z"};
inline const Keys kInvariantsPoint3d = {"position", "shape", "rotation_shape"};
inline const Keys kFeBody3d = {"name",         "type",        "position",      "orientation",     "velocity",
                               "angular_velocity", "abaqus",  "ansys", "calculix",         "modes",           "stiffness_scale",
                               "damping_ratio", "point_masses", "interfaces", "reduction", "reference", "stresses", "inertia_modes", "spin_stiffening",
                               "elastic_coordinates", "elastic_velocities"};
inline const Keys kSidBody3d = {"name",     "type",           "position",           "orientation",
                                "velocity", "angular_velocity", "file", "elastic_coordinates",
                                "elastic_velocities"};
inline const Keys kFeFilesAbaqus = {"input", "mass", "stiffness"};
inline const Keys kFeFilesAnsys = {"coordinates", "elements", "dof_map", "mass", "stiffness"};
inline const Keys kFeFilesCalculix = {"job"};
inline const Keys kFeStresses = {"calculix_frd"};
inline const Keys kFeSpinStiffening = {"calculix", "abaqus", "spin"};
inline const Keys kFeSpinAbaqus = {"stiffness"};
inline const Keys kFePointMass = {"node", "mass"};
inline const Keys kFeInterface = {"name", "kind", "nodes", "node_set", "point"};
inline const Keys kOrientation = {"quaternion", "axis", "angle", "matrix"};
inline const Keys kSpatialJoint = {"name", "type", "bodies", "frames", "world"};
inline const Keys kJointWorld = {"point", "axis", "x_axis", "orientation"};
inline const Keys kJointFrame = {"point", "axis", "orientation"};
inline const Keys kBushing = {"name", "type", "bodies", "frames", "world", "stiffness", "damping"};
inline const Keys kSpatialAppliedLoad = {"name",    "type",     "body",     "point",    "force_x",
                                         "force_y", "force_z",  "torque_x", "torque_y", "torque_z"};

// ----- kinematics scenes (flexmbd kinematics) ------------------------------------------
inline const Keys kKinematicsScene = {"name", "nodes", "links", "inputs", "analysis"};
inline const Keys kKinematicsNode = {"name", "type", "position"};  ///< fixed, free
inline const Keys kKinematicsSliderNode = {"name", "type", "position", "direction"};
inline const Keys kKinematicsLink = {"name", "nodes", "length"};
inline const Keys kLinkAngleInput = {"name", "type", "link", "node", "ratio"};
inline const Keys kNodeInput = {"name", "type", "node", "ratio"};  ///< slider_position, node_x, node_y
inline const Keys kAnalysis = {"start",          "end",       "steps",      "speed",
                               "acceleration",   "tolerance", "max_iterations", "corrector",
                               "singular_tolerance", "locate_tolerance"};

// ----- tensegrity scenes ("model": "tensegrity", flexmbd run) ----------------------------
inline const Keys kTensegrityScene = {"model", "name",  "dimension", "gravity",             "nodes",    "struts",
                                      "cables", "loads", "max_struts_per_node", "prestress", "solver"};
inline const Keys kTensegrityNode = {"name", "position", "velocity", "mass", "fixed"};
inline const Keys kStrut = {"name", "nodes", "EA", "natural_length", "mass", "mass_model", "radius"};
inline const Keys kCable = {"name", "nodes", "EA", "natural_length", "inextensible", "radius"};
inline const Keys kLoad = {"name", "node", "force"};
inline const Keys kPrestress = {"cable", "tension"};
inline const Keys kTimeSteppingSolver = {"method",         "t_start",           "t_end",         "time_step",
                                         "output_step",    "lcp",               "lcp_tolerance", "lcp_max_iterations",
                                         "projection",     "projection_tolerance", "slack_tolerance", "contacts",
                                         "contact_constraints"};
inline const Keys kMasslessCablesSolver = {"method", "t_start", "t_end",          "output_step", "rtol",
                                           "atol",   "max_step", "slack_tolerance", "contacts"};

/// Every kind of object, by the identifier its key tables carry in docs/scene-format.md.
inline const std::vector<std::pair<std::string, const Keys*>>& allObjects() {
  static const std::vector<std::pair<std::string, const Keys*>> objects = {
      {"scene", &kScene},
      {"sensitivity", &kSensitivity},
      {"body.rigid", &kRigidBody},
      {"body.flexible", &kFlexibleBody},
      {"body.flexible_invariants", &kInvariantsBody},
      {"section", &kSection},
      {"beam", &kBeam},
      {"reference.pinned_pinned", &kReferencePinnedPinned},
      {"reference.clamped", &kReferenceClamped},
      {"reference.free_free", &kReferenceFreeFree},
      {"invariants", &kInvariants},
      {"invariants.point", &kInvariantsPoint},
      {"joint.revolute", &kJoint},
      {"joint.fixed", &kJoint},
      {"joint.prismatic", &kPrismaticJoint},
      {"driver.body_angle", &kBodyDriver},
      {"driver.body_x", &kBodyDriver},
      {"driver.body_y", &kBodyDriver},
      {"driver.joint_angle", &kJointDriver},
      {"driver.joint_displacement", &kJointDriver},
      {"law.constant", &kLawConstant},
      {"law.constant_speed", &kLawConstantSpeed},
      {"law.polynomial", &kLawPolynomial},
      {"law.harmonic", &kLawHarmonic},
      {"law.spin_up", &kLawSpinUp},
      {"law.tabulated", &kLawTabulated},
      {"force.spring_damper", &kSpringDamper},
      {"force.rotational_spring_damper", &kRotationalSpringDamper},
      {"force.applied_load", &kAppliedLoad},
      {"output.energy", &kEnergyOutput},
      {"output.point", &kPointOutput},
      {"output.deflection", &kPointOutput},
      {"output.stress", &kStressOutput},
      {"solver", &kSolver},
      {"body.rigid.3d", &kRigidBody3d},
      {"shape.box", &kShapeBox},
      {"shape.sphere", &kShapeSphere},
      {"shape.cylinder", &kShapeCylinder},
      {"shape.tube", &kShapeTube},
      {"geometry.box", &kGeometryBox},
      {"geometry.sphere", &kGeometrySphere},
      {"geometry.cylinder", &kGeometryCylinder},
      {"geometry.tube", &kGeometryTube},
      {"orientation", &kOrientation},
      {"body.flexible.3d", &kFlexibleBody3d},
      {"body.flexible_invariants.3d", &kInvariantsBody3d},
      {"section.3d", &kSection3d},
      {"beam.3d", &kBeam3d},
      {"invariants.3d", &kInvariants3d},
      {"invariants.point.3d", &kInvariantsPoint3d},
      {"body.fe_body.3d", &kFeBody3d},
      {"body.sid_body.3d", &kSidBody3d},
      {"fe.files.abaqus", &kFeFilesAbaqus},
      {"fe.files.ansys", &kFeFilesAnsys},
      {"fe.files.calculix", &kFeFilesCalculix},
      {"fe.point_mass", &kFePointMass},
      {"fe.stresses", &kFeStresses},
      {"fe.spin_stiffening", &kFeSpinStiffening},
      {"fe.spin_stiffening.abaqus", &kFeSpinAbaqus},
      {"fe.interface", &kFeInterface},
      {"joint.3d.spherical", &kSpatialJoint},
      {"joint.3d.revolute", &kSpatialJoint},
      {"joint.3d.prismatic", &kSpatialJoint},
      {"joint.3d.cylindrical", &kSpatialJoint},
      {"joint.3d.universal", &kSpatialJoint},
      {"joint.3d.fixed", &kSpatialJoint},
      {"joint.3d.planar", &kSpatialJoint},
      {"joint.frame", &kJointFrame},
      {"joint.world", &kJointWorld},
      {"driver.body_z", &kBodyDriver},
      {"force.applied_load.3d", &kSpatialAppliedLoad},
      {"force.bushing", &kBushing},
      {"kinematics", &kKinematicsScene},
      {"kinematics.node.fixed", &kKinematicsNode},
      {"kinematics.node.free", &kKinematicsNode},
      {"kinematics.node.slider", &kKinematicsSliderNode},
      {"kinematics.link", &kKinematicsLink},
      {"kinematics.input.link_angle", &kLinkAngleInput},
      {"kinematics.input.slider_position", &kNodeInput},
      {"kinematics.input.node_x", &kNodeInput},
      {"kinematics.input.node_y", &kNodeInput},
      {"kinematics.analysis", &kAnalysis},
      {"tensegrity", &kTensegrityScene},
      {"tensegrity.node", &kTensegrityNode},
      {"tensegrity.strut", &kStrut},
      {"tensegrity.cable", &kCable},
      {"tensegrity.load", &kLoad},
      {"tensegrity.prestress", &kPrestress},
      {"tensegrity.solver.time_stepping", &kTimeSteppingSolver},
      {"tensegrity.solver.massless_cables", &kMasslessCablesSolver},
  };
  return objects;
}

}  // namespace flexmbd::scenekeys
