#include "scene/spatial_scene.hpp"

#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "bodies/body_geometry.hpp"
#include "bodies/shape_inertia.hpp"
#include "scene/flexible_body_reader.hpp"
#include "builders/planar_builders.hpp"
#include "builders/spatial_builders.hpp"
#include "core/errors.hpp"
#include "core/rotation_3d.hpp"
#include "forces/spatial_forces.hpp"
#include "scene/component_reader.hpp"
#include "scene/fe_body_reader.hpp"
#include "fe_import/sid_file.hpp"
#include "scene/scene_keys.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"
#include "joints/world_frames.hpp"

namespace flexmbd::scenereaders {
namespace {

using nlohmann::json;
using namespace jsonread;

Vec3 vec3(const ObjectReader& r, const std::string& key, const Vec3& fallback) {
  return r.has(key) ? Vec3(r.vector(key, 3)) : fallback;
}

/// A frame from {"point", "axis" | "orientation"}: "axis" gives the frame's z axis (body
/// axes), its x axis being the body axis least aligned with it, made orthogonal.
JointFrame parseJointFrame(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  r.allowOnly(scenekeys::kJointFrame, " for a joint frame");
  JointFrame f;
  f.point = vec3(r, "point", Vec3::Zero());
  if (r.has("axis") && r.has("orientation")) r.fail("give either \"axis\" or \"orientation\", not both");
  if (r.has("axis")) {
    const Vec3 a = r.direction("axis", 3);
    f.axes = located(r.where(), [&] { return frameAxesFromZ(a, nullptr, "key \"axis\""); });
  } else if (r.has("orientation")) {
    f.axes = parseOrientation(r.object("orientation"), r.where() + ".orientation");
  }
  return f;
}

/// Key "frames": [frameI, frameJ], one on each body.
std::array<JointFrame, 2> parseFramePair(const ObjectReader& r) {
  const json& frames = r.requiredArray("frames");
  if (frames.size() != 2) r.fail("key \"frames\" must list two frames [{...}, {...}], one on each body");
  return {parseJointFrame(frames[0], r.where() + ".frames[0]"), parseJointFrame(frames[1], r.where() + ".frames[1]")};
}

/// Joint types whose frame axes matter: the joint axis z must be given ("axis").
bool needsAxis(SpatialJointType t) { return t != SpatialJointType::Spherical && t != SpatialJointType::Fixed; }

/// Key "world": {"point", "axis", "x_axis"} or {"point", "orientation"}: one frame in world
/// axes, in the initial configuration, that both bodies' frames are made from. A universal
/// joint needs its x axis (the cross's pin on body I): "x_axis" or "orientation".
JointFrame parseWorldFrame(const json& j, const std::string& where, SpatialJointType t) {
  ObjectReader r(j, where);
  r.allowOnly(scenekeys::kJointWorld, " for a joint placed in the world");
  const Vec3 point = r.vector("point", 3);
  if (r.has("orientation")) {
    if (r.has("axis") || r.has("x_axis")) r.fail("give either \"axis\" (with \"x_axis\") or \"orientation\", not both");
    JointFrame f;
    f.point = point;
    f.axes = parseOrientation(r.object("orientation"), r.where() + ".orientation");
    return f;
  }
  if (!r.has("axis")) {
    if (needsAxis(t)) {
      r.fail(std::string("a ") + toString(t) + " joint needs key \"axis\" (its joint axis, world axes) or \"orientation\"");
    }
    if (r.has("x_axis")) r.fail("key \"x_axis\" needs key \"axis\"");
    JointFrame f;  // spherical, fixed: the world axes
    f.point = point;
    return f;
  }
  if (t == SpatialJointType::Universal && !r.has("x_axis")) {
    r.fail("a universal joint needs key \"x_axis\" (the cross's pin on the first body, world axes) with \"axis\"");
  }
  const Vec3 axis = r.direction("axis", 3);
  const Vec3 xHint = r.has("x_axis") ? Vec3(r.direction("x_axis", 3)) : Vec3::Zero();
  return located(r.where(), [&] {
    return worldJointFrame(point, axis, r.has("x_axis") ? &xHint : nullptr, "key \"x_axis\"");
  });
}

/// The frames of a joint: key "frames" (body axes) or key "world" (exactly one).
std::array<JointFrame, 2> parseJointFrames(const ObjectReader& r, const System& sys, BodyIndex bi, BodyIndex bj,
                                           SpatialJointType t) {
  if (r.has("frames") == r.has("world")) {
    r.fail("give exactly one of \"frames\" (one frame on each body, body axes) or \"world\" (a point and axes in "
           "world axes, initial configuration)");
  }
  if (r.has("frames")) return parseFramePair(r);
  const JointFrame world = parseWorldFrame(r.object("world"), r.where() + ".world", t);
  return located(r.where() + ".world", [&] { return jointFramesFromWorld(sys, bi, bj, world, "key \"point\""); });
}

/// The frames of a spatial joint (for its drivers).
const SpatialJoint& spatialJoint(const System& sys, ConstraintIndex c, const ObjectReader& r) {
  const auto* joint = dynamic_cast<const SpatialJoint*>(&sys.constraint(c));
  if (!joint) r.fail("joint " + inQuotes(sys.constraint(c).name()) + " is not a spatial joint");
  return *joint;
}

/// The frame state of a spatial body: "position", "orientation", "velocity" (world) and
/// "angular_velocity" (body axes).
FrameState3d parseFrameState3d(const ObjectReader& r) {
  FrameState3d init;
  init.position = vec3(r, "position", Vec3::Zero());
  if (r.has("orientation")) init.orientation = parseOrientation(r.object("orientation"), r.where() + ".orientation");
  init.velocity = vec3(r, "velocity", Vec3::Zero());
  init.angularVelocity = vec3(r, "angular_velocity", Vec3::Zero());
  return init;
}

/// A spatial beam section: "width" and "height" (rectangle, along the section's y and z
/// axes) or "area", "inertia_y", "inertia_z", "torsion_constant"; "youngs_modulus", one
/// of "shear_modulus" or "poisson_ratio" (G = E / (2 (1 + nu)): TimoshenkoGoodier1970), "density", "damping";
/// for Timoshenko beams "shear_factor_y" and "shear_factor_z" (a rectangle's default:
/// Cowper's factor, rectangleShearFactor; Cowper1966).
BeamSection3d parseSection3d(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  r.allowOnly(scenekeys::kSection3d, " for a spatial section");
  const double E = r.positive("youngs_modulus");
  if (r.has("shear_modulus") == r.has("poisson_ratio")) {
    r.fail("give exactly one of \"shear_modulus\" or \"poisson_ratio\"");
  }
  double G = 0.0;
  if (r.has("shear_modulus")) {
    G = r.positive("shear_modulus");
  } else {
    const double nu = r.number("poisson_ratio");
    if (!(nu > -1.0 && nu < 0.5)) r.fail("key \"poisson_ratio\" must be in (-1, 0.5), got " + fmt(nu));
    G = E / (2.0 * (1.0 + nu));  // isotropic material
  }
  const double rho = r.positive("density"), damping = r.nonNegative("damping", 0.0);
  if (r.has("width") || r.has("height")) {
    if (r.has("area") || r.has("inertia_y") || r.has("inertia_z") || r.has("torsion_constant")) {
      r.fail("give either width and height, or area, inertia_y, inertia_z and torsion_constant, not both");
    }
    BeamSection3d s = rectangularSection3d(r.positive("width"), r.positive("height"), E, G, rho, damping);
    s.shearFactorY = r.positive("shear_factor_y", s.shearFactorY);
    s.shearFactorZ = r.positive("shear_factor_z", s.shearFactorZ);
    return s;
  }
  BeamSection3d s;
  if (r.has("shear_factor_y")) s.shearFactorY = r.positive("shear_factor_y");
  if (r.has("shear_factor_z")) s.shearFactorZ = r.positive("shear_factor_z");
  s.area = r.positive("area");
  s.inertiaY = r.positive("inertia_y");
  s.inertiaZ = r.positive("inertia_z");
  s.torsionConstant = r.positive("torsion_constant");
  s.youngsModulus = E;
  s.shearModulus = G;
  s.density = rho;
  s.damping = damping;
  return s;
}

void parseSpatialFlexibleBody(const ObjectReader& r, const std::string& name, System& sys) {
  r.allowOnly(scenekeys::kFlexibleBody3d, " for a flexible body in a spatial scene");
  const BeamSection3d section = parseSection3d(r.object("section"), r.where() + ": section");
  const Vec3 yHint = vec3(r, "y_axis", Vec3::UnitY());
  BeamMesh3d mesh = readBeamMesh<BeamMesh3d>(r, {0, 0, section, yHint}, scenekeys::kBeam3d, " for a spatial beam");
  FfrBeamOptions3d options;
  readBeamModelOptions(r, static_cast<int>(mesh.nodes.size()), options);
  const FrameState3d init = parseFrameState3d(r);
  const auto model = located(r.where(), [&] {
    return std::make_shared<const FfrBeamModel3d>(std::move(mesh), options, "body '" + name + "'");
  });
  const int nf = model->numElastic();
  const VecX qf0 = readElasticState(r, "elastic_coordinates", nf);
  const VecX qf0dot = readElasticState(r, "elastic_velocities", nf);
  located(r.where(), [&] { return sys.addBody(std::make_unique<FfrBody3d>(name, model, init, qf0, qf0dot)); });
}

void parseSpatialInvariantBody(const ObjectReader& r, const std::string& name, System& sys) {
  r.allowOnly(scenekeys::kInvariantsBody3d, " for a flexible_invariants body in a spatial scene");
  const ObjectReader iv(r.object("invariants"), r.where() + ": invariants");
  iv.allowOnly(scenekeys::kInvariants3d, " for spatial invariants");
  FfrInvariants3d inv;
  inv.mass = iv.positive("mass");
  inv.firstMoment = iv.vector("first_moment", 3);
  const MatX mff = iv.matrix("m_ff");
  const int nf = static_cast<int>(mff.rows());
  inv.secondMoment = readSizedMatrix(iv, "second_moment", 3, 3, nf);
  inv.mff = readSquareInvariant(iv, "m_ff", nf);
  inv.sBar = readSizedMatrix(iv, "s_bar", 3, nf, nf);
  static const char* const kPositionShape[3] = {"position_shape_x", "position_shape_y", "position_shape_z"};
  for (int k = 0; k < 3; ++k) inv.positionShape[k] = readSizedMatrix(iv, kPositionShape[k], 3, nf, nf);
  static const char* const kSkl[3][3] = {{"s_xx", "s_xy", "s_xz"}, {nullptr, "s_yy", "s_yz"}, {nullptr, nullptr, "s_zz"}};
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      inv.sKL[k][l] = readSquareInvariant(iv, kSkl[k][l], nf);
      if (l != k) inv.sKL[l][k] = SpMat(inv.sKL[k][l].transpose());  // S_lk = S_kl^T
    }
  }
  // optional: the sections' second-order rotation (absent: none, the first-order field)
  static const char* const kRkl[3][3] = {{"r_xx", "r_xy", "r_xz"}, {nullptr, "r_yy", "r_yz"}, {nullptr, nullptr, "r_zz"}};
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      if (!iv.has(kRkl[k][l])) continue;
      inv.rKL[k][l] = readSquareInvariant(iv, kRkl[k][l], nf);
      if (l != k) inv.rKL[l][k] = inv.rKL[k][l];  // R_lk = R_kl
    }
  }
  static const char* const kH[3] = {"h_x", "h_y", "h_z"};
  for (int i = 0; i < 3; ++i) {
    if (iv.has(kH[i])) inv.hI[i] = readSquareInvariant(iv, kH[i], nf);
  }
  inv.kff = readSquareInvariant(iv, "k_ff", nf);
  inv.dff = readSquareInvariant(iv, "d_ff", nf, true);
  const json& pts = iv.array("points");
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const ObjectReader p(pts[k], iv.where() + ": points[" + std::to_string(k) + "]");
    p.allowOnly(scenekeys::kInvariantsPoint3d, " for a point of spatial invariants");
    FfrPoint3d fp;
    fp.position = p.vector("position", 3);
    fp.shape = readSizedMatrix(p, "shape", 3, nf, nf);
    fp.rotationShape = readSizedMatrix(p, "rotation_shape", 3, nf, nf);
    inv.points.push_back(fp);
  }
  const FrameState3d init = parseFrameState3d(r);
  const VecX qf0 = readElasticState(r, "elastic_coordinates", nf);
  const VecX qf0dot = readElasticState(r, "elastic_velocities", nf);
  located(r.where(), [&] { return addFlexibleBody3d(sys, name, std::move(inv), init, qf0, qf0dot); });
}

/// A body of "type": "fe_body": a solid mesh from an FE code's export, reduced to
/// free-free modes on mean axes or by Craig-Bampton (FeBodyModel; docs/fe-import.md); its
/// drawing (outer surface, stress shapes of "stresses") into `drawings`.
void parseSpatialFeBody(const ObjectReader& r, const std::string& name, const std::string& baseDir, System& sys,
                        std::vector<FeBodyDrawing>* drawings) {
  r.allowOnly(scenekeys::kFeBody3d, " for an fe_body in a spatial scene");
  const FeBodyData data = readFeBodyFiles(r, baseDir);
  const FeBodyOptions options = readFeBodyOptions(r, data, baseDir);
  const std::string owner = "body '" + name + "'";
  const FeBodyModel model = located(r.where(), [&] { return FeBodyModel(data, options, owner); });
  FeBodyDrawing drawing;
  drawing.nodeIds = data.nodeIds;
  drawing.surface = outerSurface(data);
  if (r.has("stresses")) drawing.stressShapes = readFeStressShapes(r, data, model, baseDir, owner);
  FfrInvariants3d inv = model.invariants();
  const int nf = inv.numElastic();
  const FrameState3d init = parseFrameState3d(r);
  const VecX qf0 = readElasticState(r, "elastic_coordinates", nf);
  const VecX qf0dot = readElasticState(r, "elastic_velocities", nf);
  drawing.body = located(r.where(), [&] { return addFlexibleBody3d(sys, name, std::move(inv), init, qf0, qf0dot); });
  if (drawings) drawings->push_back(std::move(drawing));
}

/// A body of "type": "sid_body": the reduced body of a SID file (bodies/sid_data.hpp,
/// fe_import/sid_file.hpp; docs/fe-import.md, "SID"), the path relative to the scene file's folder.
void parseSpatialSidBody(const ObjectReader& r, const std::string& name, const std::string& baseDir, System& sys) {
  r.allowOnly(scenekeys::kSidBody3d, " for a sid_body in a spatial scene");
  const std::string path = filePath(r, "file", baseDir);
  FfrInvariants3d inv = located(r.where(), [&] { return invariantsFromSid(readSidFile(path), "body '" + name + "'"); });
  const int nf = inv.numElastic();
  const FrameState3d init = parseFrameState3d(r);
  const VecX qf0 = readElasticState(r, "elastic_coordinates", nf);
  const VecX qf0dot = readElasticState(r, "elastic_velocities", nf);
  located(r.where(), [&] { return addFlexibleBody3d(sys, name, std::move(inv), init, qf0, qf0dot); });
}

/// The type, dimensions, "offset" and "orientation" of a shape (in "shape" and "geometry");
/// the caller has checked the keys.
SolidShape readSolidShape(const ObjectReader& r, const std::string& type) {
  SolidShape s;
  if (type == "box") {
    s.type = SolidShape::Type::Box;
    s.size = r.vector("size", 3);
    for (int k = 0; k < 3; ++k) r.checkPositive(s.size[k], "size[" + std::to_string(k) + "]");
  } else if (type == "sphere") {
    s.type = SolidShape::Type::Sphere;
    s.radius = r.positive("radius");
  } else {
    const bool tube = type == "tube";
    s.type = tube ? SolidShape::Type::Tube : SolidShape::Type::Cylinder;
    s.radius = r.positive(tube ? "outer_radius" : "radius");
    if (tube) {
      s.innerRadius = r.nonNegative("inner_radius");
      if (!(s.innerRadius < s.radius)) {
        r.fail("key \"inner_radius\" must be < outer_radius (" + fmt(s.radius) + "), got " + fmt(s.innerRadius));
      }
    }
    s.length = r.positive("length");
    const std::string axis = r.string("axis", "z");
    if (axis != "x" && axis != "y" && axis != "z") {
      r.fail("key \"axis\" must be \"x\", \"y\" or \"z\" (the shape axis along its own axis), got " + inQuotes(axis));
    }
    s.axis = axis[0] - 'x';
  }
  if (r.has("offset")) s.offset = r.vector("offset", 3);
  if (r.has("orientation")) s.orientation = parseOrientation(r.object("orientation"), r.where() + ".orientation");
  return s;
}

/// The keys allowed for each type of shape, in the order box, cylinder, tube, sphere.
using ShapeKeys = std::array<const scenekeys::Keys*, 4>;

/// A "shape" or "geometry" object's "type" and shape, its keys checked against those of
/// its type (`what` ends the message: " shape", " in \"geometry\" ...").
SolidShape readTypedShape(const ObjectReader& r, const ShapeKeys& keys, const std::string& what) {
  static const std::array<const char*, 4> types = {"box", "cylinder", "tube", "sphere"};
  const std::string type = readType(r, "shape", {"box", "cylinder", "tube", "sphere"});
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (type == types[k]) r.allowOnly(*keys[k], " for a " + type + what);
  }
  return readSolidShape(r, type);
}

/// One shape of key "shape" of a spatial rigid body: {"type": "box" | "cylinder" | "tube" |
/// "sphere", its dimensions, exactly one of "mass" or "density", optional "offset" and
/// "orientation" in body axes}.
ShapePart parseShapePart(const json& j, const std::string& where) {
  const ObjectReader r(j, where);
  static const ShapeKeys keys = {&scenekeys::kShapeBox, &scenekeys::kShapeCylinder, &scenekeys::kShapeTube,
                                 &scenekeys::kShapeSphere};
  ShapePart part;
  part.shape = readTypedShape(r, keys, " shape");
  if (r.has("mass") == r.has("density")) r.fail("give exactly one of \"mass\" or \"density\"");
  part.mass = r.has("mass") ? r.positive("mass") : 0.0;
  part.density = r.has("density") ? r.positive("density") : 0.0;
  return part;
}

/// An array of shapes or one shape {...}, each object read by `read`.
template <class T, class Read>
std::vector<T> readShapeList(const json& j, const std::string& where, Read read) {
  const auto one = [&](const json& v, const std::string& at) {
    if (!v.is_object()) throw InputError(at + ": must be a shape {\"type\": ...}, got " + describe(v));
    return read(v, at);
  };
  std::vector<T> out;
  if (j.is_array()) {
    if (j.empty()) throw InputError(where + ": an array of shapes must have at least one shape");
    for (std::size_t k = 0; k < j.size(); ++k) out.push_back(one(j[k], where + "[" + std::to_string(k) + "]"));
  } else {
    out.push_back(one(j, where));
  }
  return out;
}

/// Key "shape" of a spatial rigid body: one shape, or an array of them whose centre of
/// mass is the body origin.
RigidBody3dProperties parseShape(const json& j, const std::string& where) {
  const std::vector<ShapePart> parts = readShapeList<ShapePart>(j, where, parseShapePart);
  return located(where, [&] { return shapeProperties(parts); });
}

}  // namespace

Mat3 parseOrientation(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  r.allowOnly(scenekeys::kOrientation, " for an orientation");
  const int forms = (r.has("quaternion") ? 1 : 0) + (r.has("axis") || r.has("angle") ? 1 : 0) + (r.has("matrix") ? 1 : 0);
  if (forms != 1) {
    r.fail("give exactly one of \"quaternion\": [e0, e1, e2, e3], \"axis\" with \"angle\", or \"matrix\": [[...], [...], [...]]");
  }
  if (r.has("quaternion")) {
    const Vec4 p = r.vector("quaternion", 4);
    if (!(p.norm() > 0.0)) r.fail("key \"quaternion\" must be non-zero");
    return quaternionRotation(p);
  }
  if (r.has("matrix")) {
    const MatX m = r.matrix("matrix");
    if (m.rows() != 3 || m.cols() != 3) r.fail("key \"matrix\" must be 3 rows of 3 numbers");
    const Mat3 A = m;
    if (!((A.transpose() * A - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) || !(A.determinant() > 0.0)) {
      r.fail("key \"matrix\" is not a rotation (expected orthonormal rows, determinant +1, to 1e-9)");
    }
    return A;
  }
  if (!r.has("axis") || !r.has("angle")) r.fail("an axis-angle orientation needs both \"axis\" and \"angle\"");
  const Vec3 axis = r.direction("axis", 3);
  return quaternionRotation(quaternionFromAxisAngle(axis, r.number("angle")));
}

std::vector<SolidShape> parseGeometry(const json& j, const std::string& where) {
  return readShapeList<SolidShape>(j, where, [](const json& v, const std::string& at) {
    const ObjectReader r(v, at);
    static const ShapeKeys keys = {&scenekeys::kGeometryBox, &scenekeys::kGeometryCylinder,
                                   &scenekeys::kGeometryTube, &scenekeys::kGeometrySphere};
    SolidShape s = readTypedShape(r, keys, " in \"geometry\" (viewing only: no mass)");
    located(r.where(), [&] { return surfaceMesh(s); });  // the dimensions' checks
    return s;
  });
}

void parseSpatialBody(const json& j, const std::string& where, System& sys, const std::string& baseDir,
                      std::vector<FeBodyDrawing>* drawings) {
  ObjectReader r(j, where);
  const auto [type, name] = readBodyTypeAndName(r);
  if (type == "fe_body") return parseSpatialFeBody(r, name, baseDir, sys, drawings);
  if (type == "sid_body") return parseSpatialSidBody(r, name, baseDir, sys);
  if (type == "flexible") return parseSpatialFlexibleBody(r, name, sys);
  if (type == "flexible_invariants") return parseSpatialInvariantBody(r, name, sys);
  r.allowOnly(scenekeys::kRigidBody3d, " for a rigid body in a spatial scene");
  const FrameState3d init = parseFrameState3d(r);
  if (r.has("shape") == r.has("inertia")) {
    r.fail("give exactly one of \"inertia\" (with \"mass\") or \"shape\" (mass and inertia of a solid shape)");
  }
  if (r.has("shape")) {
    if (r.has("mass")) r.fail("key \"mass\" does not go with \"shape\": give the shape's \"mass\" or \"density\"");
    const RigidBody3dProperties props = parseShape(r.required("shape"), r.where() + ".shape");
    located(r.where(), [&] { return sys.addBody(std::make_unique<RigidBody3d>(name, props, init)); });
    return;
  }
  RigidBody3dProperties props;
  props.mass = r.positive("mass");
  const json& inertia = r.required("inertia");
  const bool numbers = inertia.is_array() && !inertia.empty() && !inertia[0].is_array();
  if (!inertia.is_array() || (numbers && inertia.size() != 3)) {
    r.fail("key \"inertia\" must be 3 principal moments [Ixx, Iyy, Izz] or a 3 x 3 tensor [[...], [...], [...]] "
           "(kg m^2, about the centre of mass), got " +
           (inertia.is_array() ? std::to_string(inertia.size()) + " numbers" : std::string("a ") + inertia.type_name()));
  }
  if (numbers) {
    const Vec3 I = r.vector("inertia", 3);
    for (int k = 0; k < 3; ++k) r.checkPositive(I[k], "inertia[" + std::to_string(k) + "]");
    props.inertia = I.asDiagonal();
  } else {
    const MatX m = r.matrix("inertia");
    if (m.rows() != 3 || m.cols() != 3) {
      r.fail("key \"inertia\" must be 3 principal moments [Ixx, Iyy, Izz] or a 3 x 3 tensor [[...], [...], [...]]");
    }
    props.inertia = m;
  }
  located(r.where(), [&] { return sys.addBody(std::make_unique<RigidBody3d>(name, props, init)); });
}

void parseSpatialJoint(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  if (readRegisteredComponent("joints", 3, r, sys)) return;
  std::vector<std::string> known = {"spherical", "revolute", "prismatic", "cylindrical", "universal", "fixed", "planar"};
  for (const std::string& t : registeredTypes("joints", 3)) known.push_back(t);
  const std::string type = readType(r, "joint", known);
  r.allowOnly(scenekeys::kSpatialJoint, " for a joint in a spatial scene");
  const std::string name = r.name("name");
  const auto [bi, bj] = lookupBodyPair(sys, r, "a joint");
  static const std::array<std::pair<const char*, SpatialJointType>, 7> types = {{
      {"spherical", SpatialJointType::Spherical}, {"revolute", SpatialJointType::Revolute},
      {"prismatic", SpatialJointType::Prismatic}, {"cylindrical", SpatialJointType::Cylindrical},
      {"universal", SpatialJointType::Universal}, {"fixed", SpatialJointType::Fixed},
      {"planar", SpatialJointType::Planar}}};
  SpatialJointType t = SpatialJointType::Spherical;
  for (const auto& [n, v] : types) {
    if (type == n) t = v;
  }
  const auto [fi, fj] = parseJointFrames(r, sys, bi, bj, t);
  located(r.where(), [&] { return sys.addConstraint(std::make_unique<SpatialJoint>(name, t, bi, fi, bj, fj)); });
}

void parseSpatialDriver(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  const std::string type =
      readType(r, "driver", {"body_x", "body_y", "body_z", "body_angle", "joint_angle", "joint_displacement"});
  if (type == "body_angle") {
    r.fail("a body_angle driver is planar; in a spatial scene drive a revolute joint's angle (joint_angle)");
  }
  const bool onJoint = type == "joint_angle" || type == "joint_displacement";
  r.allowOnly(onJoint ? scenekeys::kJointDriver : scenekeys::kBodyDriver, " for a " + type + " driver");
  const std::string name = r.name("name");
  if (!onJoint) {
    const BodyIndex body = lookupBody(sys, r.name("body"), r);
    TimeLawPtr law = parseTimeLaw(r.object("law"), r.where() + ".law");
    const std::string coordinate = type.substr(5);
    located(r.where(), [&] { return addBodyCoordinateDriver(sys, name, body, coordinate, law); });
    return;
  }
  const std::string jointName = r.name("joint");
  if (readDriverOfRegisteredJoint(type, name, lookupJoint(sys, jointName, r), r, sys)) return;
  const SpatialJoint& joint = spatialJoint(sys, lookupJoint(sys, jointName, r), r);
  const SpatialJointType jt = joint.type();
  const bool angle = type == "joint_angle";
  const bool fits = jt == SpatialJointType::Cylindrical ||
                    (angle ? jt == SpatialJointType::Revolute : jt == SpatialJointType::Prismatic);
  if (!fits) {
    r.fail("a " + type + " driver needs a " + (angle ? "revolute or cylindrical" : "prismatic or cylindrical") +
           " joint, but joint " + inQuotes(jointName) + " is " + joint.typeName());
  }
  TimeLawPtr law = parseTimeLaw(r.object("law"), r.where() + ".law");
  const BodyIndex bi = joint.bodies()[0], bj = joint.bodies()[1];
  located(r.where(), [&] {
    if (angle) {
      return sys.addConstraint(
          std::make_unique<SpatialJointAngleDriver>(name, bi, joint.frameI(), bj, joint.frameJ(), law));
    }
    return sys.addConstraint(
        std::make_unique<SpatialJointDisplacementDriver>(name, bi, joint.frameI(), bj, joint.frameJ(), law));
  });
}

void parseSpatialForce(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  const std::string type =
      readType(r, "force", {"spring_damper", "rotational_spring_damper", "applied_load", "bushing"});
  const std::string forA = " for a " + type + " force in a spatial scene";
  if (type == "bushing") {
    r.allowOnly(scenekeys::kBushing, forA);
    const std::string name = r.name("name");
    const auto [bi, bj] = lookupBodyPair(sys, r, "a bushing");
    const auto [fi, fj] = parseJointFrames(r, sys, bi, bj, SpatialJointType::Fixed);  // "frames" or "world"
    std::array<double, 6> k{}, c{};
    const VecX kv = r.vector("stiffness", 6);
    const VecX cv = r.has("damping") ? r.vector("damping", 6) : VecX::Zero(6);
    for (int a = 0; a < 6; ++a) {
      k[a] = r.checkNonNegative(kv[a], "stiffness[" + std::to_string(a) + "]");
      c[a] = r.checkNonNegative(cv[a], "damping[" + std::to_string(a) + "]");
    }
    located(r.where(), [&] { return sys.addForce(std::make_unique<SpatialBushing>(name, bi, fi, bj, fj, k, c)); });
    return;
  }
  if (type == "rotational_spring_damper") {
    r.allowOnly(scenekeys::kRotationalSpringDamper, forA);
    const std::string name = r.name("name");
    const std::string jointName = r.name("joint");
    const ConstraintIndex jointIndex = lookupJoint(sys, jointName, r);
    const SpatialJoint& joint = spatialJoint(sys, jointIndex, r);
    if (joint.type() != SpatialJointType::Revolute && joint.type() != SpatialJointType::Cylindrical) {
      r.fail("a rotational_spring_damper needs a revolute or cylindrical joint, but joint " + inQuotes(jointName) +
             " is " + joint.typeName());
    }
    const double stiffness = r.nonNegative("stiffness");
    const double damping = r.nonNegative("damping", 0.0);
    const BodyIndex bi = joint.bodies()[0], bj = joint.bodies()[1];
    double freeAngle = 0.0;
    if (r.has("free_angle")) {
      freeAngle = r.number("free_angle");
    } else {
      // the joint angle in the initial positions
      freeAngle = located(r.where(), [&] { return initialJointAngle(sys, jointIndex); });
    }
    located(r.where(), [&] {
      return sys.addForce(std::make_unique<SpatialRotationalSpringDamper>(name, bi, joint.frameI(), bj, joint.frameJ(),
                                                                          stiffness, damping, freeAngle));
    });
    return;
  }
  if (type == "spring_damper") {
    r.allowOnly(scenekeys::kSpringDamper, forA);
    const std::string name = r.name("name");
    const auto [bi, bj] = lookupBodyPair(sys, r, "a spring");
    const json& points = r.requiredArray("points");
    if (points.size() != 2 || !points[0].is_array() || !points[1].is_array()) {
      r.fail("key \"points\" must be two points [[xi, yi, zi], [xj, yj, zj]]");
    }
    const MatX P = r.matrix("points");
    if (P.cols() != 3) r.fail("key \"points\" must be two points [[xi, yi, zi], [xj, yj, zj]]");
    const Vec3 pi = P.row(0).transpose(), pj = P.row(1).transpose();
    const SpringDamperLaw law = readSpringDamperLaw(r, [&] {
      return (sys.body(bj).frameKinematics(sys.body(bj).initialCoordinates(), pj).r -
              sys.body(bi).frameKinematics(sys.body(bi).initialCoordinates(), pi).r).norm();
    });
    located(r.where(), [&] {
      return sys.addForce(
          std::make_unique<SpatialSpringDamper>(name, bi, pi, bj, pj, law.stiffness, law.damping, law.freeLength));
    });
    return;
  }
  r.allowOnly(scenekeys::kSpatialAppliedLoad, forA);
  const std::string name = r.name("name");
  const BodyIndex body = lookupBody(sys, r.name("body"), r);
  const Vec3 point = vec3(r, "point", Vec3::Zero());
  std::array<TimeLawPtr, 6> laws;
  static const std::array<const char*, 6> keys = {"force_x", "force_y", "force_z", "torque_x", "torque_y", "torque_z"};
  bool any = false;
  for (int k = 0; k < 6; ++k) {
    if (!r.has(keys[k])) continue;
    laws[k] = parseTimeLaw(r.object(keys[k]), r.where() + "." + keys[k]);
    any = true;
  }
  if (!any) r.fail("an applied_load needs at least one of the keys \"force_x\" ... \"torque_z\" (each a law object)");
  located(r.where(), [&] { return sys.addForce(std::make_unique<SpatialAppliedLoad>(name, body, point, laws)); });
}

}  // namespace flexmbd::scenereaders
