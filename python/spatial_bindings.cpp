// Python bindings of the spatial builders (builders/spatial_builders.hpp) and the objects
// they take: frame states and orientations, rigid body properties and solid shapes, joint
// frames, spatial beam sections, meshes and models. Names are the C++ ones in snake case
// (docs/python.md, "Spatial models"). Every argument is converted with an error naming
// the function and the argument.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings_support.hpp"
#include "user_functions.hpp"
#include "bodies/fe_body_model.hpp"
#include "bodies/sid_data.hpp"
#include "fe_import/sid_file.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "bodies/shape_inertia.hpp"
#include "builders/spatial_builders.hpp"
#include "core/magnitude_checks.hpp"
#include "elements/beam_section.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "fe_import/fe_ansys.hpp"
#include "joints/world_frames.hpp"

namespace flexmbd::pybind {

namespace {

using Law = std::shared_ptr<TimeLaw>;

/// A rotation given as a 3 x 3 matrix (body axes in world axes: its columns), 4 Euler
/// parameters (e0, e1, e2, e3) or an (axis, angle) pair; None: the identity.
Mat3 orientationArg(const py::handle& h, const char* fn, const char* arg) {
  if (h.is_none()) return Mat3::Identity();
  constexpr const char* expected =
      "a rotation: a 3 x 3 matrix, a quaternion (e0, e1, e2, e3) or an (axis, angle) pair";
  if (py::isinstance<py::str>(h)) badArgument(fn, arg, expected, h);
  try {
    const Mat3 R = h.cast<Mat3>();
    if (!R.allFinite() || !((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) ||
        !(R.determinant() > 0.0)) {
      throw InputError(std::string(fn) + ": " + arg +
                       " is not a rotation matrix (expected orthonormal columns, determinant +1, to 1e-9)");
    }
    return R;
  } catch (const py::cast_error&) {
  }
  try {
    const Vec4 p = h.cast<Vec4>();
    if (!p.allFinite() || !(p.norm() > 0.0)) {
      throw InputError(std::string(fn) + ": " + arg + ": the quaternion must be finite and not all zero");
    }
    return rotationFromQuaternion(p);
  } catch (const py::cast_error&) {
  }
  if (py::isinstance<py::sequence>(h) && py::len(h) == 2) {
    const py::sequence s = h.cast<py::sequence>();
    Vec3 axis;
    double angle = 0.0;
    try {
      axis = s[0].cast<Vec3>();
      angle = s[1].cast<double>();
    } catch (const py::cast_error&) {
      badArgument(fn, arg, expected, h);
    }
    const Vec3 unit = unitDirection(axis, std::string(fn) + ": " + arg + ": the axis");
    if (!std::isfinite(angle)) throw InputError(std::string(fn) + ": " + arg + ": the angle must be finite");
    return rotationFromAxisAngle(unit, angle);
  }
  badArgument(fn, arg, expected, h);
}

/// 3 principal moments (body axes) or a 3 x 3 tensor.
Mat3 inertiaArg(const py::handle& h, const char* fn) {
  constexpr const char* expected = "3 principal moments (Ixx, Iyy, Izz) or a 3 x 3 tensor";
  if (py::isinstance<py::str>(h) || h.is_none()) badArgument(fn, "inertia", expected, h);
  try {
    return h.cast<Mat3>();
  } catch (const py::cast_error&) {
  }
  try {
    const Vec3 I = h.cast<Vec3>();
    for (int k = 0; k < 3; ++k) {
      if (!(I[k] > 0.0) || !std::isfinite(I[k])) {
        throw InputError(std::string(fn) + ": inertia[" + std::to_string(k) + "] must be > 0, got " +
                         std::to_string(I[k]));
      }
    }
    return I.asDiagonal();
  } catch (const py::cast_error&) {
  }
  badArgument(fn, "inertia", expected, h);
}

double positiveArg(const py::handle& h, const char* fn, const char* arg) {
  const double v = numberArg(h, fn, arg);
  if (!(v > 0.0) || !std::isfinite(v)) throw InputError(std::string(fn) + ": " + arg + " must be > 0, got " + pyRepr(h));
  return v;
}
double nonNegativeArg(const py::handle& h, const char* fn, const char* arg) {
  const double v = numberArg(h, fn, arg);
  if (!(v >= 0.0) || !std::isfinite(v)) {
    throw InputError(std::string(fn) + ": " + arg + " must be >= 0, got " + pyRepr(h));
  }
  return v;
}
int intArg(const py::handle& h, const char* fn, const char* arg) {
  if (!py::isinstance<py::int_>(h) || py::isinstance<py::bool_>(h)) badArgument(fn, arg, "an integer", h);
  try {
    return h.cast<int>();
  } catch (const py::cast_error&) {  // beyond int: pybind11's RuntimeError names nothing
    throw InputError(std::string(fn) + ": " + arg + " is beyond the range of an int, got " + pyRepr(h));
  }
}

JointFrame frameArg(const py::handle& h, const char* fn, const char* arg) {
  if (h.is_none()) return JointFrame{};
  if (!py::isinstance<JointFrame>(h)) badArgument(fn, arg, "a JointFrame (flexmbd.JointFrame(point, axis=...))", h);
  return h.cast<JointFrame>();
}

SpatialJointType jointTypeArg(const py::handle& h, const char* fn) {
  if (py::isinstance<SpatialJointType>(h)) return h.cast<SpatialJointType>();
  if (!py::isinstance<py::str>(h)) badArgument(fn, "type", "a joint type name (\"revolute\", ...) or SpatialJointType", h);
  try {
    return spatialJointTypeFromString(h.cast<std::string>());
  } catch (const InputError& e) {
    throw InputError(std::string(fn) + ": type: " + e.what());
  }
}

std::array<double, 6> sixArg(const py::handle& h, const char* fn, const char* arg) {
  if (h.is_none()) return {};
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  const Vec6 v = argumentAs<Vec6>(h, fn, arg, "6 numbers (x, y, z, rx, ry, rz)");
  std::array<double, 6> a{};
  for (int k = 0; k < 6; ++k) a[k] = v[k];
  return a;
}

/// Shear modulus from exactly one of shear_modulus or poisson_ratio (isotropic: G = E / (2 (1 + nu)),
/// TimoshenkoGoodier1970).
double shearModulusArg(double E, const py::handle& G, const py::handle& nu, const char* fn) {
  if (G.is_none() == nu.is_none()) throw InputError(std::string(fn) + ": give exactly one of shear_modulus or poisson_ratio");
  if (!G.is_none()) return positiveArg(G, fn, "shear_modulus");
  const double v = numberArg(nu, fn, "poisson_ratio");
  if (!(v > -1.0 && v < 0.5)) throw InputError(std::string(fn) + ": poisson_ratio must be in (-1, 0.5), got " + pyRepr(nu));
  return E / (2.0 * (1.0 + v));
}


int axisIndexArg(const py::handle& h, const char* fn) {
  if (py::isinstance<py::str>(h)) {
    const std::string a = h.cast<std::string>();
    if (a == "x" || a == "y" || a == "z") return a[0] - 'x';
  }
  throw InputError(std::string(fn) + ": axis must be \"x\", \"y\" or \"z\" (the body axis along the shape's axis), got " +
                   pyRepr(h));
}

bool isSpatialBody(const Body& b) {
  return dynamic_cast<const RigidBody3d*>(&b) != nullptr || dynamic_cast<const FfrBody3d*>(&b) != nullptr;
}

// ----- orientations, frame states, rigid body properties ---------------------------------
/// Rotations, FrameState3d and RigidBody3dProperties.
void bindOrientationsAndFrameStates(py::module_& m) {
  m.def(
      "rotation_from_axis_angle",
      [](const py::object& axis, const py::object& angle) {
        return rotationFromAxisAngle(vec3Arg(axis, "rotation_from_axis_angle", "axis"),
                                     numberArg(angle, "rotation_from_axis_angle", "angle"));
      },
      py::arg("axis"), py::arg("angle"), "The rotation matrix by angle (rad) about axis (C++ rotationFromAxisAngle)");
  m.def(
      "rotation_from_quaternion",
      [](const py::object& q) {
        return rotationFromQuaternion(argumentAs<Vec4>(q, "rotation_from_quaternion", "quaternion", "4 numbers (e0, e1, e2, e3)"));
      },
      py::arg("quaternion"), "The rotation matrix of Euler parameters (e0, e1, e2, e3), normalised");

  py::class_<FrameState3d>(m, "FrameState3d", "The state of a spatial body frame (initial values of a body)")
      .def(py::init([](const py::object& position, const py::object& orientation, const py::object& velocity,
                       const py::object& angularVelocity) {
             constexpr const char* fn = "FrameState3d";
             FrameState3d s;
             s.position = vec3Arg(position, fn, "position");
             s.orientation = orientationArg(orientation, fn, "orientation");
             s.velocity = vec3Arg(velocity, fn, "velocity");
             s.angularVelocity = vec3Arg(angularVelocity, fn, "angular_velocity");
             return s;
           }),
           py::arg("position") = py::make_tuple(0, 0, 0), py::arg("orientation") = py::none(),
           py::arg("velocity") = py::make_tuple(0, 0, 0), py::arg("angular_velocity") = py::make_tuple(0, 0, 0),
           "Initial state of a spatial body frame: position and velocity (world), orientation (a 3 x 3 rotation "
           "matrix, a quaternion (e0, e1, e2, e3) or an (axis, angle) pair), angular velocity (body axes)")
      .def_readwrite("position", &FrameState3d::position, "origin of the frame, world axes (m)")
      .def_readwrite("orientation", &FrameState3d::orientation, "rotation matrix from body to world axes")
      .def_readwrite("velocity", &FrameState3d::velocity, "velocity of the origin, world axes (m/s)")
      .def_readwrite("angular_velocity", &FrameState3d::angularVelocity, "angular velocity, body axes (rad/s)");

  py::class_<RigidBody3dProperties>(m, "RigidBody3dProperties",
                                            "Mass and inertia of a spatial rigid body (add_rigid_body_3d)")
      .def(py::init([](const py::object& mass, const py::object& inertia) {
             RigidBody3dProperties p;
             p.mass = positiveArg(mass, "RigidBody3dProperties", "mass");
             p.inertia = inertiaArg(inertia, "RigidBody3dProperties");
             return p;
           }),
           py::arg("mass"), py::arg("inertia"),
           "Mass (kg) and inertia about the centre of mass (body axes: 3 principal moments or a 3 x 3 tensor)")
      .def_readwrite("mass", &RigidBody3dProperties::mass, "kg")
      .def_readwrite("inertia", &RigidBody3dProperties::inertia, "3 x 3 inertia tensor about the centre of mass, body axes (kg m^2)");
}

// ----- solid shapes (bodies/shape_inertia.hpp) -----------------------------------------------
/// SolidShape, ShapePart, CompositeInertia and the shapes' inertia functions.
void bindSolidShapes(py::module_& m) {
  py::class_<SolidShape>(m, "SolidShape",
                          "A solid of simple shape (box, cylinder, tube, sphere): inertia from geometry")
      .def_static(
          "box",
          [](const py::object& size) {
            SolidShape s;
            s.type = SolidShape::Type::Box;
            s.size = vec3Arg(size, "SolidShape.box", "size");
            return s;
          },
          py::arg("size"), "A box of edge lengths (along body x, y, z), centred on the body frame")
      .def_static(
          "cylinder",
          [](const py::object& radius, const py::object& length, const py::object& axis) {
            SolidShape s;
            s.type = SolidShape::Type::Cylinder;
            s.radius = positiveArg(radius, "SolidShape.cylinder", "radius");
            s.length = positiveArg(length, "SolidShape.cylinder", "length");
            s.axis = axisIndexArg(axis, "SolidShape.cylinder");
            return s;
          },
          py::arg("radius"), py::arg("length"), py::arg("axis") = "z",
          "A solid cylinder of its radius and length along the body axis \"x\", \"y\" or \"z\", centred on the body frame")
      .def_static(
          "tube",
          [](const py::object& outer, const py::object& inner, const py::object& length, const py::object& axis) {
            constexpr const char* fn = "SolidShape.tube";
            SolidShape s;
            s.type = SolidShape::Type::Tube;
            s.radius = positiveArg(outer, fn, "outer_radius");
            s.innerRadius = nonNegativeArg(inner, fn, "inner_radius");
            if (!(s.innerRadius < s.radius)) throw InputError(std::string(fn) + ": inner_radius must be < outer_radius");
            s.length = positiveArg(length, fn, "length");
            s.axis = axisIndexArg(axis, fn);
            return s;
          },
          py::arg("outer_radius"), py::arg("inner_radius"), py::arg("length"), py::arg("axis") = "z",
          "A tube (hollow cylinder) along the body axis \"x\", \"y\" or \"z\", centred on the body frame")
      .def_static(
          "sphere",
          [](const py::object& radius) {
            SolidShape s;
            s.type = SolidShape::Type::Sphere;
            s.radius = positiveArg(radius, "SolidShape.sphere", "radius");
            return s;
          },
          py::arg("radius"), "A solid sphere of its radius, centred on the body frame")
      .def_property_readonly("volume", [](const SolidShape& s) { return shapeVolume(s); }, "the shape's volume (m^3)")
      .def_readwrite("offset", &SolidShape::offset, "the shape's centre in body axes (m)")
      .def_readwrite("orientation", &SolidShape::orientation, "the shape's axes in body axes (rotation matrix)")
      .def(
          "placed",
          [](SolidShape s, const py::object& offset, const py::object& orientation) {
            s.offset = vec3Arg(offset, "SolidShape.placed", "offset");
            if (!orientation.is_none()) s.orientation = orientationArg(orientation, "SolidShape.placed", "orientation");
            return s;
          },
          py::arg("offset"), py::arg("orientation") = py::none(),
          "A copy of the shape with its centre at offset and its axes turned by orientation (body axes)");
  const auto shapePart = [](const SolidShape& s, const py::object& mass, const py::object& density, const char* fn) {
    if (mass.is_none() == density.is_none()) throw InputError(std::string(fn) + ": give exactly one of mass or density");
    return mass.is_none() ? ShapePart{s, 0.0, positiveArg(density, fn, "density")}
                          : ShapePart{s, positiveArg(mass, fn, "mass"), 0.0};
  };
  py::class_<ShapePart>(m, "ShapePart", "A shape of a body with its mass or density (composite_inertia, shape_properties)")
      .def(py::init([shapePart](const SolidShape& s, const py::object& mass, const py::object& density) {
             return shapePart(s, mass, density, "ShapePart");
           }),
           py::arg("shape"), py::arg("mass") = py::none(), py::arg("density") = py::none(),
           "One shape of a body with exactly one of its mass (kg) or density (kg/m^3)")
      .def_readonly("shape", &ShapePart::shape, "the SolidShape")
      .def_readonly("mass", &ShapePart::mass, "kg, or 0 when the density is given")
      .def_readonly("density", &ShapePart::density, "kg/m^3, or 0 when the mass is given");
  py::class_<CompositeInertia>(m, "CompositeInertia", "Mass, centre of mass and inertia of several shapes together")
      .def_readonly("mass", &CompositeInertia::mass, "kg")
      .def_readonly("centre_of_mass", &CompositeInertia::centreOfMass, "body axes (m)")
      .def_readonly("inertia", &CompositeInertia::inertia, "about the centre of mass, body axes (kg m^2)");
  m.def("composite_inertia", &compositeInertia, py::arg("parts"),
        "Mass, centre of mass and inertia about it (body axes) of several placed shapes");
  m.def(
      "shape_properties",
      [shapePart](const SolidShape& s, const py::object& mass, const py::object& density) {
        return shapeProperties(std::vector<ShapePart>{shapePart(s, mass, density, "shape_properties")});
      },
      py::arg("shape"), py::arg("mass") = py::none(), py::arg("density") = py::none(),
      "RigidBody3dProperties of a body that is the shape: the mass given, or density x volume");
  m.def("shape_properties", py::overload_cast<const std::vector<ShapePart>&>(&shapeProperties), py::arg("parts"),
        "RigidBody3dProperties of a body made of several shapes whose centre of mass is the body origin");
  m.def("shape_volume", &shapeVolume, py::arg("shape"), "The volume of a SolidShape (m^3)");
  m.def(
      "shape_inertia", [](const SolidShape& s, const py::object& mass) { return shapeInertia(s, positiveArg(mass, "shape_inertia", "mass")); },
      py::arg("shape"), py::arg("mass"),
      "The 3 x 3 inertia tensor (kg m^2) of a shape of that mass about its centre, in body axes");
}

// ----- joint frames (joints/frame_pair.hpp, joints/world_frames.hpp) -------------------------
/// JointFrame, world_joint_frame and SpatialJointType.
void bindJointFrames(py::module_& m) {
  py::class_<JointFrame>(m, "JointFrame", "A frame fixed in a body (or in the world) that a spatial joint or bushing connects")
      .def(py::init([](const py::object& point, const py::object& axis, const py::object& orientation) {
             constexpr const char* fn = "JointFrame";
             if (!axis.is_none() && !orientation.is_none()) throw InputError("JointFrame: give either axis or orientation, not both");
             const Vec3 p = vec3Arg(point, fn, "point");
             if (!axis.is_none()) return jointFrameFromAxis(p, vec3Arg(axis, fn, "axis"));
             JointFrame f;
             f.point = p;
             f.axes = orientationArg(orientation, fn, "orientation");
             return f;
           }),
           py::arg("point") = py::make_tuple(0, 0, 0), py::arg("axis") = py::none(), py::arg("orientation") = py::none(),
           "A frame fixed in a body (body axes): origin point; z axis along axis (x: the body axis least aligned "
           "with it, made perpendicular), or the axes of a rotation (orientation), or the body axes")
      .def_readwrite("point", &JointFrame::point, "origin (body or world axes, m)")
      .def_readwrite("axes", &JointFrame::axes, "3 x 3 rotation matrix whose columns are the frame's x, y, z axes");
  m.def(
      "world_joint_frame",
      [](const py::object& point, const py::object& axis, const py::object& xAxis) {
        constexpr const char* fn = "world_joint_frame";
        const Vec3 p = vec3Arg(point, fn, "point"), a = vec3Arg(axis, fn, "axis");
        if (xAxis.is_none()) return worldJointFrame(p, a, nullptr, fn);
        const Vec3 x = vec3Arg(xAxis, fn, "x_axis");
        return worldJointFrame(p, a, &x, fn);
      },
      py::arg("point"), py::arg("axis"), py::arg("x_axis") = py::none(),
      "A frame in world axes: origin point, z along axis, x along x_axis made perpendicular (C++ worldJointFrame)");
  py::enum_<SpatialJointType>(m, "SpatialJointType", "The kinds of spatial joint (add_spatial_joint; or their names as strings)")
      .value("SPHERICAL", SpatialJointType::Spherical)
      .value("REVOLUTE", SpatialJointType::Revolute)
      .value("PRISMATIC", SpatialJointType::Prismatic)
      .value("CYLINDRICAL", SpatialJointType::Cylindrical)
      .value("UNIVERSAL", SpatialJointType::Universal)
      .value("FIXED", SpatialJointType::Fixed)
      .value("PLANAR", SpatialJointType::Planar);
}

// ----- spatial beams (elements/beam_section.hpp, bodies/ffr_beam_model_3d.hpp) -----------------
/// Spatial beam sections, meshes, options and models.
void bindSpatialBeams(py::module_& m) {
  py::class_<BeamSection3d>(m, "BeamSection3d", "Cross-section and material of a spatial beam (section axes y, z: principal axes)")
      .def(py::init([](const py::object& area, const py::object& iy, const py::object& iz, const py::object& j,
                       const py::object& E, const py::object& G, const py::object& nu, const py::object& rho,
                       const py::object& damping, const py::object& kappaY, const py::object& kappaZ) {
             constexpr const char* fn = "BeamSection3d";
             BeamSection3d s;
             s.area = positiveArg(area, fn, "area");
             s.inertiaY = positiveArg(iy, fn, "inertia_y");
             s.inertiaZ = positiveArg(iz, fn, "inertia_z");
             s.torsionConstant = positiveArg(j, fn, "torsion_constant");
             s.youngsModulus = positiveArg(E, fn, "youngs_modulus");
             s.shearModulus = shearModulusArg(s.youngsModulus, G, nu, fn);
             s.density = positiveArg(rho, fn, "density");
             s.damping = nonNegativeArg(damping, fn, "damping");
             s.shearFactorY = nonNegativeArg(kappaY, fn, "shear_factor_y");  // Timoshenko only
             s.shearFactorZ = nonNegativeArg(kappaZ, fn, "shear_factor_z");
             return s;
           }),
           py::arg("area"), py::arg("inertia_y"), py::arg("inertia_z"), py::arg("torsion_constant"),
           py::arg("youngs_modulus"), py::arg("shear_modulus") = py::none(), py::arg("poisson_ratio") = py::none(),
           py::arg("density"), py::arg("damping") = 0.0, py::arg("shear_factor_y") = 0.0,
           py::arg("shear_factor_z") = 0.0)
      .def_readwrite("area", &BeamSection3d::area, "A (m^2)")
      .def_readwrite("inertia_y", &BeamSection3d::inertiaY, "Iy = int z^2 dA (m^4): bending in the x-z plane")
      .def_readwrite("inertia_z", &BeamSection3d::inertiaZ, "Iz = int y^2 dA (m^4): bending in the x-y plane")
      .def_readwrite("torsion_constant", &BeamSection3d::torsionConstant, "St Venant torsion constant J (m^4)")
      .def_readwrite("youngs_modulus", &BeamSection3d::youngsModulus, "Young's modulus E (Pa)")
      .def_readwrite("shear_modulus", &BeamSection3d::shearModulus, "G (Pa)")
      .def_readwrite("density", &BeamSection3d::density, "rho (kg/m^3)")
      .def_readwrite("damping", &BeamSection3d::damping, "stiffness-proportional damping beta (s): D = beta K")
      .def_readwrite("shear_factor_y", &BeamSection3d::shearFactorY, "shear correction factor kappa_y (Timoshenko; 0: not given)")
      .def_readwrite("shear_factor_z", &BeamSection3d::shearFactorZ, "shear correction factor kappa_z (Timoshenko; 0: not given)");
  m.def(
      "rectangular_section_3d",
      [](const py::object& w, const py::object& h, const py::object& E, const py::object& G, const py::object& nu,
         const py::object& rho, const py::object& damping) {
        constexpr const char* fn = "rectangular_section_3d";
        const double e = positiveArg(E, fn, "youngs_modulus");
        return rectangularSection3d(positiveArg(w, fn, "width"), positiveArg(h, fn, "height"), e,
                                    shearModulusArg(e, G, nu, fn), positiveArg(rho, fn, "density"),
                                    nonNegativeArg(damping, fn, "damping"));
      },
      py::arg("width"), py::arg("height"), py::arg("youngs_modulus"), py::arg("shear_modulus") = py::none(),
      py::arg("poisson_ratio") = py::none(), py::arg("density"), py::arg("damping") = 0.0,
      "width along the section's y axis, height along z; exactly one of shear_modulus or poisson_ratio");
  m.def(
      "circular_section_3d",
      [](const py::object& d, const py::object& E, const py::object& G, const py::object& nu, const py::object& rho,
         const py::object& damping) {
        constexpr const char* fn = "circular_section_3d";
        const double e = positiveArg(E, fn, "youngs_modulus");
        return circularSection3d(positiveArg(d, fn, "diameter"), e, shearModulusArg(e, G, nu, fn),
                                 positiveArg(rho, fn, "density"), nonNegativeArg(damping, fn, "damping"));
      },
      py::arg("diameter"), py::arg("youngs_modulus"), py::arg("shear_modulus") = py::none(),
      py::arg("poisson_ratio") = py::none(), py::arg("density"), py::arg("damping") = 0.0,
      "A solid circular section of that diameter (m): E (Pa), G (Pa) or Poisson's ratio, density (kg/m^3)");
  py::class_<BeamMesh3d>(m, "BeamMesh3d", "A spatial beam mesh: nodes (body frame) and 2-node elements with their sections")
      .def(py::init([](const std::vector<Vec3>& nodes, const std::vector<std::pair<int, int>>& elements,
                       const BeamSection3d& section, const py::object& yAxis) {
             BeamMesh3d mesh;
             mesh.nodes = nodes;
             const Vec3 y = vec3Arg(yAxis, "BeamMesh3d", "y_axis");
             for (const auto& [a, b] : elements) mesh.elements.push_back({a, b, section, y});
             return mesh;
           }),
           py::arg("nodes"), py::arg("elements"), py::arg("section"), py::arg("y_axis") = py::make_tuple(0, 1, 0),
           "nodes [[x, y, z], ...] (body frame), elements [(i, j), ...] with one section and y axis hint")
      .def_static(
          "straight",
          [](const py::object& length, const py::object& elements, const BeamSection3d& section, const py::object& origin,
             const py::object& yAxis) {
            constexpr const char* fn = "BeamMesh3d.straight";
            return BeamMesh3d::straight(positiveArg(length, fn, "length"), intArg(elements, fn, "elements"), section,
                                        vec3Arg(origin, fn, "origin"), vec3Arg(yAxis, fn, "y_axis"));
          },
          py::arg("length"), py::arg("elements"), py::arg("section"), py::arg("origin") = py::make_tuple(0, 0, 0),
          py::arg("y_axis") = py::make_tuple(0, 1, 0), "A straight beam along the body x axis from origin")
      .def_readonly("nodes", &BeamMesh3d::nodes, "the nodes' positions (body frame, m)");
  py::enum_<ReferenceConditions3d::Type>(m, "Reference3d",
                                            "Reference conditions of a spatial beam's body frame (default CLAMPED at node_a)")
      .value("CLAMPED", ReferenceConditions3d::Type::Clamped)
      .value("PINNED_PINNED", ReferenceConditions3d::Type::PinnedPinned)
      .value("FREE_FREE", ReferenceConditions3d::Type::FreeFree);
  py::enum_<BeamTheory>(m, "BeamTheory", "The beam theory of a spatial beam model (docs/spatial-flexible.md)")
      .value("EULER_BERNOULLI", BeamTheory::EulerBernoulli)
      .value("RAYLEIGH", BeamTheory::Rayleigh)
      .value("TIMOSHENKO", BeamTheory::Timoshenko);
  py::class_<FfrBeamOptions3d>(m, "FfrBeamOptions3d",
                                "Options of a spatial beam model: reference conditions, modes kept, stiffening, theory")
      .def(py::init([](ReferenceConditions3d::Type type, int nodeA, int nodeB, int modes, std::vector<int> modeSet,
                       bool stiffening, ModalReduction reduction, std::vector<int> interfaceNodes, bool inertiaModes,
                       BeamTheory theory) {
             FfrBeamOptions3d o;
             o.reference.type = type;
             o.reference.nodeA = nodeA;
             o.reference.nodeB = nodeB;
             o.modes = modes;
             o.modeSet = std::move(modeSet);
             o.geometricStiffening = stiffening;
             o.reduction = reduction;
             o.interfaceNodes = std::move(interfaceNodes);
             o.inertiaModes = inertiaModes;
             o.theory = theory;
             return o;
           }),
           py::arg("reference") = ReferenceConditions3d::Type::Clamped, py::arg("node_a") = 0, py::arg("node_b") = -1,
           py::arg("modes") = 0, py::arg("mode_set") = std::vector<int>{}, py::arg("geometric_stiffening") = false,
           py::arg("reduction") = ModalReduction::Normal, py::arg("interface_nodes") = std::vector<int>{},
           py::arg("inertia_modes") = false, py::arg("theory") = BeamTheory::EulerBernoulli,
           "reference conditions (clamped at node_a by default), modes (0: nodal), mode_set, geometric stiffening, "
           "modal reduction (normal or Craig-Bampton with interface_nodes), inertia modes, beam theory");
  py::class_<FfrBeamModel3d, std::shared_ptr<FfrBeamModel3d>>(
      m, "FfrBeamModel3d", "A spatial beam mesh as a floating-frame body model (add_flexible_body_3d)")
      .def(py::init([](BeamMesh3d mesh, const FfrBeamOptions3d& o, const std::string& owner) {
             return std::make_shared<FfrBeamModel3d>(std::move(mesh), o, owner);
           }),
           py::arg("mesh"), py::arg("options"), py::arg("owner") = "beam model",
           "The model of the mesh under the options; owner names it in messages")
      .def("natural_frequencies", &FfrBeamModel3d::naturalFrequencies, "rad/s, ascending (frame held fixed)")
      .def_property_readonly("num_elastic", &FfrBeamModel3d::numElastic, "number of elastic coordinates nf")
      .def_property_readonly(
          "invariants", [](const FfrBeamModel3d& mdl) { return mdl.invariants(); },
          "A copy of the model's invariants (FfrInvariants3d), to change or to add as a body of its own");
}

// ----- given invariants (bodies/ffr_invariants_3d.hpp): NumPy arrays in, sparse inside ----
/// FfrPoint3d and FfrInvariants3d.
void bindGivenInvariants(py::module_& m) {
  py::class_<FfrPoint3d>(m, "FfrPoint3d", "An attachment point of given invariants (FfrInvariants3d.points)")
      .def(py::init([](const py::object& position, const py::object& shape, const py::object& rotationShape) {
             // converted to the fields' own 3 x nf types: a matrix of other rows is a
             // TypeError here (assigned as MatX it overran the field's memory)
             using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;
             FfrPoint3d p;
             p.position = vec3Arg(position, "FfrPoint3d", "position");
             p.shape = argumentAs<Mat3X>(shape, "FfrPoint3d", "shape", "a 3 x nf matrix");
             p.rotationShape = argumentAs<Mat3X>(rotationShape, "FfrPoint3d", "rotation_shape", "a 3 x nf matrix");
             return p;
           }),
           py::arg("position"), py::arg("shape"), py::arg("rotation_shape"),
           "An attachment point: undeformed position u0 (body axes), shape N (3 x nf), rotation shape (3 x nf)")
      .def_readwrite("position", &FfrPoint3d::position, "undeformed position u0, body axes (m)")
      .def_readwrite("shape", &FfrPoint3d::shape, "N, 3 x nf: displacement = N q_f")
      .def_readwrite("rotation_shape", &FfrPoint3d::rotationShape, "Ntheta, 3 x nf: small rotation = Ntheta q_f");
  const auto sparseField = [](SpMat FfrInvariants3d::*field) {
    return std::make_pair([field](const FfrInvariants3d& v) { return MatX(v.*field); },
                          [field](FfrInvariants3d& v, const MatX& x) { v.*field = x.sparseView(); });
  };
  const auto [mffGet, mffSet] = sparseField(&FfrInvariantsBase<3>::mff);
  const auto [kffGet, kffSet] = sparseField(&FfrInvariantsBase<3>::kff);
  const auto [dffGet, dffSet] = sparseField(&FfrInvariantsBase<3>::dff);
  using Pairs = std::vector<std::vector<MatX>>;
  const auto pairsGet = [](const std::array<std::array<SpMat, 3>, 3>& a) {
    Pairs out(3, std::vector<MatX>(3));
    for (int k = 0; k < 3; ++k) for (int l = 0; l < 3; ++l) out[k][l] = MatX(a[k][l]);
    return out;
  };
  const auto pairsSet = [](std::array<std::array<SpMat, 3>, 3>& a, const Pairs& x, const char* what) {
    if (x.size() != 3 || x[0].size() != 3 || x[1].size() != 3 || x[2].size() != 3) {
      throw InputError(std::string("FfrInvariants3d.") + what + ": expected 3 lists of 3 matrices (k, l in x, y, z)");
    }
    for (int k = 0; k < 3; ++k) for (int l = 0; l < 3; ++l) a[k][l] = x[k][l].sparseView();
  };
  py::class_<FfrInvariants3d>(m, "FfrInvariants3d",
                              "The inertia and stiffness invariants of a spatial FFR body (docs/spatial-flexible.md); "
                              "matrices are NumPy arrays (kept sparse inside); checked when a body is added")
      .def(py::init<>())
      .def_readwrite("mass", &FfrInvariants3d::mass, "m = int rho dV (kg)")
      .def_readwrite("first_moment", &FfrInvariants3d::firstMoment, "int rho u0 dV (kg m)")
      .def_readwrite("s_bar", &FfrInvariants3d::sBar, "S-bar = int rho N dV (3 x nf)")
      .def_property("m_ff", mffGet, mffSet, "m_ff = int rho N^T N dV (nf x nf)")
      .def_property("k_ff", kffGet, kffSet, "stiffness under the reference conditions (nf x nf)")
      .def_property("d_ff", dffGet, dffSet, "damping matrix (nf x nf)")
      // copies both ways, as the matrices: def_readwrite handed out references into the
      // vector, left dangling (a use after free) once the list was set again
      .def_property(
          "points", [](const FfrInvariants3d& v) { return v.points; },
          [](FfrInvariants3d& v, const std::vector<FfrPoint3d>& x) { v.points = x; },
          "the attachment points (FfrPoint3d), a copy")
      .def_readwrite("second_moment", &FfrInvariants3d::secondMoment, "int rho u0 u0^T dV (3 x 3)")
      .def_property(
          "position_shape", [](const FfrInvariants3d& v) { return std::vector<MatX>(v.positionShape.begin(), v.positionShape.end()); },
          [](FfrInvariants3d& v, const std::vector<MatX>& x) {
            // checked before the assignment: a MatX of other rows would overrun the 3 x nf field
            if (x.size() != 3 || x[0].rows() != 3 || x[1].rows() != 3 || x[2].rows() != 3) {
              throw InputError("FfrInvariants3d.position_shape: expected 3 matrices (x, y, z), 3 x nf each");
            }
            for (int k = 0; k < 3; ++k) v.positionShape[k] = x[k];
          },
          "3 matrices (x, y, z), 3 x nf: row l of k = int rho u0_k N_l dV")
      .def_property(
          "s_kl", [pairsGet](const FfrInvariants3d& v) { return pairsGet(v.sKL); },
          [pairsSet](FfrInvariants3d& v, const Pairs& x) { pairsSet(v.sKL, x, "s_kl"); },
          "3 lists of 3 matrices: S_kl = int rho N_k^T N_l dV (nf x nf)")
      .def_property(
          "r_kl", [pairsGet](const FfrInvariants3d& v) { return pairsGet(v.rKL); },
          [pairsSet](FfrInvariants3d& v, const Pairs& x) { pairsSet(v.rKL, x, "r_kl"); },
          "3 lists of 3 matrices R_kl: the sections' second-order rotation (empty: none)")
      .def_property(
          "h_i", [](const FfrInvariants3d& v) { return std::vector<MatX>{MatX(v.hI[0]), MatX(v.hI[1]), MatX(v.hI[2])}; },
          [](FfrInvariants3d& v, const std::vector<MatX>& x) {
            if (x.size() != 3) throw InputError("FfrInvariants3d.h_i: expected 3 matrices (x, y, z), nf x nf each");
            for (int k = 0; k < 3; ++k) v.hI[k] = x[k].sparseView();
          },
          "3 matrices H_i (nf x nf): coupling of the sections' second-order displacement (empty: none)")
      .def_property(
          "spin_stiffness", [pairsGet](const FfrInvariants3d& v) { return pairsGet(v.spinStiffness); },
          [pairsSet](FfrInvariants3d& v, const Pairs& x) { pairsSet(v.spinStiffness, x, "spin_stiffness"); },
          "3 lists of 3 matrices G_kl: geometric stiffness of a steady spin per w_k w_l (empty: none)")
      .def_property_readonly("num_elastic", [](const FfrInvariants3d& v) { return v.mff.rows(); },
                             "number of elastic coordinates nf")
      .def(
          "validate", [](const FfrInvariants3d& v, const std::string& owner) {
            v.validate(owner);
            v.validateSectionRotation(owner);
          },
          py::arg("owner") = "invariants", "@raises InputError naming the offending invariant");
}

// ----- the SID of a body (bodies/sid_data.hpp, fe_import/sid_file.hpp) ----------------------------
/// write_sid and read_sid.
void bindSid(py::module_& m) {
  m.def(
      "write_sid", [](const FfrInvariants3d& inv, const std::string& path) { writeSidFile(sidFromInvariants(inv), path); },
      py::arg("invariants"), py::arg("path"),
      "Writes the Standard Input Data (SID text file) of spatial invariants (docs/fe-import.md, \"SID\")");
  m.def(
      "read_sid", [](const std::string& path, const std::string& owner) { return invariantsFromSid(readSidFile(path), owner); },
      py::arg("path"), py::arg("owner") = "SID body",
      "The invariants of a SID text file; InputError names the file and line, or the block and entry");
}

// ----- bodies from FE codes (bodies/fe_body_model.hpp, fe_import/fe_abaqus.hpp, fe_import/fe_ansys.hpp) ----
/// FeBodyData, the Abaqus and Ansys readers and FeBodyModel.
void bindFeBodies(py::module_& m) {
  py::class_<FeBodyData>(m, "FeBodyData", "A body exported from an FE code: nodes, elements, node sets, M and K")
      .def_property_readonly("num_nodes", &FeBodyData::numNodes, "number of nodes")
      .def_property_readonly("num_dofs", &FeBodyData::numDofs, "number of degrees of freedom of M and K")
      .def_readonly("node_ids", &FeBodyData::nodeIds, "the FE code's node numbers")
      .def_readonly("coordinates", &FeBodyData::coordinates, "undeformed node positions, in node order (m)")
      .def_readonly("node_sets", &FeBodyData::nodeSets, "node indices (not numbers), by set name")
      .def_readonly("source", &FeBodyData::source, "the files read, for messages");
  m.def("read_abaqus_fe", &readAbaqusFe, py::arg("input"), py::arg("mass"), py::arg("stiffness"),
        "An Abaqus export: the .inp and the *MATRIX GENERATE mass and stiffness (.mtx); InputError names the file "
        "and line");
  m.def(
      "read_ansys_fe",
      [](const std::string& coordinates, const std::string& elements, const std::string& dofMap,
         const std::string& mass, const std::string& stiffness) {
        return readAnsysFe(AnsysFeFiles{coordinates, elements, dofMap, mass, stiffness});
      },
      py::arg("coordinates"), py::arg("elements"), py::arg("dof_map"), py::arg("mass"), py::arg("stiffness"),
      "An Ansys export (MatrixMarket matrices, DOF map, tables); InputError names the file and line");
  py::class_<FeBodyModel, std::shared_ptr<FeBodyModel>>(m, "FeBodyModel",
                                                        "An FE body reduced to free-free modes on mean axes")
      .def(py::init([](const FeBodyData& data, const py::object& modes, const py::object& scale,
                       const py::object& damping, const std::vector<std::pair<int, double>>& pointMasses,
                       const std::vector<py::dict>& interfaces, const std::string& reduction,
                       const std::string& reference, bool inertiaModes, const std::string& owner) {
             constexpr const char* fn = "FeBodyModel";
             FeBodyOptions o;
             o.modes = intArg(modes, fn, "modes");
             o.stiffnessScale = positiveArg(scale, fn, "stiffness_scale");
             o.dampingRatio = nonNegativeArg(damping, fn, "damping_ratio");
             for (const auto& [id, mass] : pointMasses) {
               const int a = data.nodeIndex(id);
               if (a < 0) throw InputError(std::string(fn) + ": point_masses: no node " + std::to_string(id));
               o.pointMasses.push_back({a, mass});
             }
             // interfaces: dicts as the scene's objects, {"name", "kind", "nodes" | "node_set", "point"}
             for (const py::dict& d : interfaces) {
               FeInterface f;
               for (const auto& item : d) {
                 const std::string key = py::str(item.first);
                 if (key != "name" && key != "kind" && key != "nodes" && key != "node_set" && key != "point") {
                   throw InputError(std::string(fn) + ": interfaces: unknown key '" + key +
                                    "' (expected name, kind, nodes or node_set, point)");
                 }
               }
               f.name = d.contains("name") ? py::str(d["name"]).cast<std::string>() : std::string("interface");
               const std::string kind = d.contains("kind") ? d["kind"].cast<std::string>() : "averaging";
               if (kind != "rigid" && kind != "averaging") {
                 throw InputError(std::string(fn) + ": interface '" + f.name + "': kind must be 'rigid' or 'averaging'");
               }
               f.kind = kind == "rigid" ? FeInterfaceKind::Rigid : FeInterfaceKind::Averaging;
               if (d.contains("node_set") == d.contains("nodes")) {
                 throw InputError(std::string(fn) + ": interface '" + f.name + "': give exactly one of nodes or node_set");
               }
               if (d.contains("node_set")) {
                 const std::string set = d["node_set"].cast<std::string>();
                 const auto it = data.nodeSets.find(set);
                 if (it == data.nodeSets.end()) {
                   throw InputError(std::string(fn) + ": interface '" + f.name + "': no node set '" + set + "'");
                 }
                 f.nodes = it->second;
               } else {
                 for (int id : d["nodes"].cast<std::vector<int>>()) {
                   const int a = data.nodeIndex(id);
                   if (a < 0) throw InputError(std::string(fn) + ": interface '" + f.name + "': no node " + std::to_string(id));
                   f.nodes.push_back(a);
                 }
               }
               if (d.contains("point")) {
                 f.atCentroid = false;
                 f.point = vec3Arg(d["point"], fn, "interfaces[].point");
               }
               o.interfaces.push_back(std::move(f));
             }
             if (reduction != "free_free" && reduction != "craig_bampton") {
               throw InputError(std::string(fn) + ": reduction must be 'free_free' or 'craig_bampton', got '" + reduction + "'");
             }
             if (reduction == "craig_bampton") {
               o.reduction = FeReduction::CraigBampton;
               o.reference = reference;
             }
             o.inertiaModes = inertiaModes;
             return std::make_shared<FeBodyModel>(data, o, owner);
           }),
           py::arg("data"), py::arg("modes") = 8, py::arg("stiffness_scale") = 1.0, py::arg("damping_ratio") = 0.0,
           py::arg("point_masses") = std::vector<std::pair<int, double>>{},
           py::arg("interfaces") = std::vector<py::dict>{}, py::arg("reduction") = "free_free",
           py::arg("reference") = "", py::arg("inertia_modes") = false, py::arg("owner") = "FE body",
           "point_masses: [(FE node number, kg), ...]; interfaces: [{'name', 'kind': 'rigid' | 'averaging', "
           "'nodes': [numbers] or 'node_set': name, 'point': (x, y, z)}, ...]; reduction 'free_free' or "
           "'craig_bampton' with reference (a rigid interface's name); inertia_modes: append the static "
           "responses to the frame's inertia loads")
      .def_property_readonly(
          "invariants", [](const FeBodyModel& mdl) { return mdl.invariants(); },
          "A copy of the reduced invariants (FfrInvariants3d): add them with System.add_flexible_body_3d")
      .def_property_readonly("natural_frequencies", &FeBodyModel::naturalFrequencies, "rad/s, the kept modes");
}

/// System.add_rigid_body_3d and add_flexible_body_3d.
void bindSpatialBodyBuilders(py::class_<System>& system) {
  system
      .def(
          "add_rigid_body_3d",
          [](System& s, const std::string& name, const py::object& props, const py::object& init) {
            constexpr const char* fn = "add_rigid_body_3d";
            if (!py::isinstance<RigidBody3dProperties>(props)) {
              badArgument(fn, "properties", "RigidBody3dProperties (or flexmbd.shape_properties(...))", props);
            }
            if (!init.is_none() && !py::isinstance<FrameState3d>(init)) badArgument(fn, "initial", "a FrameState3d", init);
            return addRigidBody3d(s, name, props.cast<RigidBody3dProperties>(),
                                  init.is_none() ? FrameState3d{} : init.cast<FrameState3d>());
          },
          py::arg("name"), py::arg("properties"), py::arg("initial") = py::none(),
          "A spatial rigid body (RigidBody3dProperties, FrameState3d; None: at rest at the origin): its BodyIndex")
      .def(
          "add_flexible_body_3d",
          [](System& s, const std::string& name, const py::object& model, const py::object& init,
             std::optional<VecX> qf, std::optional<VecX> qfDot) {
            constexpr const char* fn = "add_flexible_body_3d";
            if (!init.is_none() && !py::isinstance<FrameState3d>(init)) badArgument(fn, "initial", "a FrameState3d", init);
            const FrameState3d initial = init.is_none() ? FrameState3d{} : init.cast<FrameState3d>();
            if (py::isinstance<FfrInvariants3d>(model)) {
              return addFlexibleBody3d(s, name, model.cast<FfrInvariants3d>(), initial, qf ? *qf : VecX(),
                                       qfDot ? *qfDot : VecX());
            }
            if (!py::isinstance<FfrBeamModel3d>(model)) badArgument(fn, "model", "an FfrBeamModel3d or FfrInvariants3d", model);
            return addFlexibleBody3d(s, name, std::shared_ptr<const FfrBeamModel3d>(model.cast<std::shared_ptr<FfrBeamModel3d>>()),
                                     initial, qf ? *qf : VecX(), qfDot ? *qfDot : VecX());
          },
          py::arg("name"), py::arg("model"), py::arg("initial") = py::none(),
          py::arg("elastic_coordinates") = py::none(), py::arg("elastic_velocities") = py::none(),
          "A spatial FFR body of a beam model (FfrBeamModel3d) or of given invariants (FfrInvariants3d)");
}

/// The spatial joints and their drivers; initial_joint_angle.
void bindSpatialJointBuilders(py::class_<System>& system) {
  system
      .def(
          "add_spatial_joint",
          [](System& s, const std::string& name, const py::object& type, const py::object& bi, const py::object& fi,
             const py::object& bj, const py::object& fj) {
            constexpr const char* fn = "add_spatial_joint";
            return addSpatialJoint(s, name, jointTypeArg(type, fn), body(s, bi, fn, "body_i"), frameArg(fi, fn, "frame_i"),
                                   body(s, bj, fn, "body_j"), frameArg(fj, fn, "frame_j"));
          },
          py::arg("name"), py::arg("type"), py::arg("body_i"), py::arg("frame_i"), py::arg("body_j"), py::arg("frame_j"),
          "A joint between frame_i of body_i and frame_j of body_j (JointFrame, body axes; None: the body frame)")
      .def(
          "add_spatial_joint_at_world",
          [](System& s, const std::string& name, const py::object& type, const py::object& bi, const py::object& bj,
             const py::object& point, const py::object& axis, const py::object& xAxis, const py::object& orientation) {
            constexpr const char* fn = "add_spatial_joint_at_world";
            const SpatialJointType t = jointTypeArg(type, fn);
            const BodyIndex i = body(s, bi, fn, "body_i"), j = body(s, bj, fn, "body_j");
            const Vec3 p = vec3Arg(point, fn, "point");
            if (!orientation.is_none()) {
              if (!axis.is_none() || !xAxis.is_none()) throw InputError(std::string(fn) + ": give either axis (with x_axis) or orientation, not both");
              JointFrame w;
              w.point = p;
              w.axes = orientationArg(orientation, fn, "orientation");
              return addSpatialJointAtWorld(s, name, t, i, j, w);
            }
            std::optional<Vec3> a, x;
            if (!axis.is_none()) a = vec3Arg(axis, fn, "axis");
            if (!xAxis.is_none()) x = vec3Arg(xAxis, fn, "x_axis");
            return addSpatialJointAtWorld(s, name, t, i, j, p, a ? &*a : nullptr, x ? &*x : nullptr);
          },
          py::arg("name"), py::arg("type"), py::arg("body_i"), py::arg("body_j"), py::arg("point"),
          py::arg("axis") = py::none(), py::arg("x_axis") = py::none(), py::arg("orientation") = py::none(),
          "A joint placed in the world (initial configuration): point, joint axis (not for spherical and fixed "
          "joints), x_axis (universal joints: the cross's pin on body_i), or the frame's orientation")
      .def(
          "add_joint_angle_driver",
          [](System& s, const std::string& name, const py::object& j, const py::object& law) {
            constexpr const char* fn = "add_joint_angle_driver";
            const Law l = lawArg(law, fn, "law");
            if (!l) badArgument(fn, "law", "a time law", law);
            return addJointAngleDriver(s, name, joint(s, j, fn, "joint"), l);
          },
          py::arg("name"), py::arg("joint"), py::arg("law"),
          "Drives the angle of a spatial revolute or cylindrical joint (name or index) by a time law (rad)")
      .def(
          "add_joint_displacement_driver",
          [](System& s, const std::string& name, const py::object& j, const py::object& law) {
            constexpr const char* fn = "add_joint_displacement_driver";
            const Law l = lawArg(law, fn, "law");
            if (!l) badArgument(fn, "law", "a time law", law);
            return addJointDisplacementDriver(s, name, joint(s, j, fn, "joint"), l);
          },
          py::arg("name"), py::arg("joint"), py::arg("law"),
          "Drives the displacement of a spatial prismatic or cylindrical joint (name or index) by a time law (m)")
      .def(
          "initial_joint_angle",
          [](const System& s, const py::object& j) { return initialJointAngle(s, joint(s, j, "initial_joint_angle")); },
          py::arg("joint"), "The angle of a spatial joint (name or index) at the initial coordinates (rad)");
}

/// Spatial spring-dampers, bushings and applied loads.
void bindSpatialForceBuilders(py::class_<System>& system) {
  system
      .def(
          "add_spatial_spring_damper",
          [](System& s, const std::string& name, const py::object& bi, const py::object& pi, const py::object& bj,
             const py::object& pj, const py::object& k, const py::object& c, const py::object& l0,
             const py::object& law) {
            constexpr const char* fn = "add_spatial_spring_damper";
            const SpringLawPtr userLaw = springLawArg(law, fn);
            requireLinearOrLaw(userLaw, k, c, fn);
            std::optional<double> freeLength;
            if (!l0.is_none()) freeLength = nonNegativeArg(l0, fn, "free_length");
            return addSpatialSpringDamper(s, name, body(s, bi, fn, "body_i"), vec3Arg(pi, fn, "point_i"),
                                          body(s, bj, fn, "body_j"), vec3Arg(pj, fn, "point_j"),
                                          userLaw ? 0.0 : nonNegativeArg(k, fn, "stiffness"),
                                          userLaw ? 0.0 : nonNegativeArg(c, fn, "damping"), freeLength, userLaw);
          },
          py::arg("name"), py::arg("body_i"), py::arg("point_i"), py::arg("body_j"), py::arg("point_j"),
          py::arg("stiffness") = py::none(), py::arg("damping") = 0.0, py::arg("free_length") = py::none(),
          py::arg("law") = py::none(),
          "free_length None: the points' initial distance; law: a user law f(t, l, ldot) (flexmbd.spring_law or a "
          "callable) in place of stiffness (l - free_length) + damping ldot")
      .def(
          "add_spatial_rotational_spring_damper",
          [](System& s, const std::string& name, const py::object& j, const py::object& k, const py::object& c,
             const py::object& a0, const py::object& law) {
            constexpr const char* fn = "add_spatial_rotational_spring_damper";
            const SpringLawPtr userLaw = springLawArg(law, fn);
            requireLinearOrLaw(userLaw, k, c, fn);
            std::optional<double> freeAngle;
            if (!a0.is_none()) freeAngle = numberArg(a0, fn, "free_angle");
            return addSpatialRotationalSpringDamper(s, name, joint(s, j, fn, "joint"),
                                                    userLaw ? 0.0 : nonNegativeArg(k, fn, "stiffness"),
                                                    userLaw ? 0.0 : nonNegativeArg(c, fn, "damping"), freeAngle, userLaw);
          },
          py::arg("name"), py::arg("joint"), py::arg("stiffness") = py::none(), py::arg("damping") = 0.0,
          py::arg("free_angle") = py::none(), py::arg("law") = py::none(),
          "free_angle None: the joint's initial angle; law: a user torque law tau(t, theta, theta_dot) "
          "(flexmbd.spring_law or a callable; theta within half a turn of free_angle) in place of "
          "stiffness (theta - free_angle) + damping theta_dot")
      .def(
          "add_spatial_bushing",
          [](System& s, const std::string& name, const py::object& bi, const py::object& fi, const py::object& bj,
             const py::object& fj, const py::object& k, const py::object& c) {
            constexpr const char* fn = "add_spatial_bushing";
            if (k.is_none()) badArgument(fn, "stiffness", "6 numbers (x, y, z, rx, ry, rz)", k);
            return addSpatialBushing(s, name, body(s, bi, fn, "body_i"), frameArg(fi, fn, "frame_i"),
                                     body(s, bj, fn, "body_j"), frameArg(fj, fn, "frame_j"), sixArg(k, fn, "stiffness"),
                                     sixArg(c, fn, "damping"));
          },
          py::arg("name"), py::arg("body_i"), py::arg("frame_i"), py::arg("body_j"), py::arg("frame_j"),
          py::arg("stiffness"), py::arg("damping") = py::none(),
          "A bushing between frame_i of body_i and frame_j of body_j: 6 stiffnesses and dampings (x, y, z, rx, ry, "
          "rz; along and about frame_i's axes)")
      .def(
          "add_spatial_bushing_at_world",
          [](System& s, const std::string& name, const py::object& bi, const py::object& bj, const py::object& world,
             const py::object& k, const py::object& c) {
            constexpr const char* fn = "add_spatial_bushing_at_world";
            if (!py::isinstance<JointFrame>(world)) {
              badArgument(fn, "world", "a JointFrame in world axes (flexmbd.world_joint_frame(point, axis) or "
                                       "JointFrame(point, axis=...))", world);
            }
            if (k.is_none()) badArgument(fn, "stiffness", "6 numbers (x, y, z, rx, ry, rz)", k);
            return addSpatialBushingAtWorld(s, name, body(s, bi, fn, "body_i"), body(s, bj, fn, "body_j"),
                                            world.cast<JointFrame>(), sixArg(k, fn, "stiffness"), sixArg(c, fn, "damping"));
          },
          py::arg("name"), py::arg("body_i"), py::arg("body_j"), py::arg("world"), py::arg("stiffness"),
          py::arg("damping") = py::none(),
          "A bushing placed by one frame in world axes (initial configuration): it starts undeflected")
      .def(
          "add_spatial_applied_load",
          [](System& s, const std::string& name, const py::object& b, const py::object& point, const py::object& fx,
             const py::object& fy, const py::object& fz, const py::object& tx, const py::object& ty,
             const py::object& tz) {
            constexpr const char* fn = "add_spatial_applied_load";
            const std::array<TimeLawPtr, 6> laws = {lawArg(fx, fn, "force_x"),  lawArg(fy, fn, "force_y"),
                                                    lawArg(fz, fn, "force_z"),  lawArg(tx, fn, "torque_x"),
                                                    lawArg(ty, fn, "torque_y"), lawArg(tz, fn, "torque_z")};
            return addSpatialAppliedLoad(s, name, body(s, b, fn, "body"), vec3Arg(point, fn, "point"), laws);
          },
          py::arg("name"), py::arg("body"), py::arg("point") = py::make_tuple(0, 0, 0), py::arg("force_x") = py::none(),
          py::arg("force_y") = py::none(), py::arg("force_z") = py::none(), py::arg("torque_x") = py::none(),
          py::arg("torque_y") = py::none(), py::arg("torque_z") = py::none(), "Force and torque laws, world axes");
}

}  // namespace

void bindSpatial(py::module_& m, py::class_<System>& system) {
  bindOrientationsAndFrameStates(m);
  bindSolidShapes(m);
  bindJointFrames(m);
  bindSpatialBeams(m);
  bindGivenInvariants(m);
  bindSid(m);
  bindFeBodies(m);

  // ----- the builders: methods of System ------------------------------------------------------
  bindSpatialBodyBuilders(system);
  bindSpatialJointBuilders(system);
  bindSpatialForceBuilders(system);
  system
      .def_property_readonly(
          "is_spatial",
          [](const System& s) {
            for (int b = 1; b < s.numBodies(); ++b) {
              if (isSpatialBody(s.body(BodyIndex(b)))) return true;
            }
            return false;
          },
          "True if a body is spatial (its outputs are spatial)");
}

}  // namespace flexmbd::pybind
