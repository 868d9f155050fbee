// Strict reader of scene files (docs/scene-format.md). Every object is checked for
// unknown keys before anything else (a typo is reported as such, not as a missing key),
// every number for type and finiteness, every name reference against what exists.
// Errors are one line: "<location>: <what is wrong>, got <what was found>".
#include "scene/scene.hpp"

#include "bodies/fe_stress.hpp"
#include "scene/json_reader.hpp"
#include "scene/flexible_body_reader.hpp"
#include "scene/component_reader.hpp"
#include "scene/scene_keys.hpp"
#include "scene/spatial_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "core/errors.hpp"
#include "core/magnitude_checks.hpp"
#include "core/system_evaluation.hpp"
#include "joints/point_pair.hpp"

namespace flexmbd {
namespace scenereaders {

using nlohmann::json;
using namespace jsonread;

BodyIndex lookupBody(const System& sys, const std::string& name, const ObjectReader& r) {
  std::vector<std::string> known;
  for (int i = 0; i < sys.numBodies(); ++i) {
    if (sys.body(BodyIndex(i)).name() == name) return BodyIndex(i);
    known.push_back(sys.body(BodyIndex(i)).name());
  }
  r.fail("unknown body " + inQuotes(name) + " (known bodies: " + join(known) + ")");
}

std::array<BodyIndex, 2> lookupBodyPair(const System& sys, const ObjectReader& r, const std::string& what) {
  const auto names = r.namePair("bodies");
  const BodyIndex bi = lookupBody(sys, names[0], r);
  const BodyIndex bj = lookupBody(sys, names[1], r);
  if (bi == bj) {
    r.fail("key \"bodies\" names the same body twice (" + inQuotes(names[0]) + "); " + what +
           " connects two different bodies");
  }
  return {bi, bj};
}

/// A joint (not a driver) by name.
ConstraintIndex lookupJoint(const System& sys, const std::string& name, const ObjectReader& r) {
  std::vector<std::string> known;
  for (int i = 0; i < sys.numConstraints(); ++i) {
    const Constraint& c = sys.constraint(ConstraintIndex(i));
    if (c.isDriver()) continue;
    if (c.name() == name) return ConstraintIndex(i);
    known.push_back(c.name());
  }
  r.fail("unknown joint " + inQuotes(name) + " (known joints: " + (known.empty() ? "none" : join(known)) + ")");
}

SpringDamperLaw readSpringDamperLaw(const ObjectReader& r, const std::function<double()>& initialLength) {
  SpringDamperLaw law;
  law.stiffness = r.nonNegative("stiffness");
  law.damping = r.nonNegative("damping", 0.0);
  law.freeLength = r.has("free_length") ? r.nonNegative("free_length") : located(r.where(), initialLength);
  return law;
}

}  // namespace scenereaders

namespace {

using scenereaders::lookupBody;
using scenereaders::lookupBodyPair;
using scenereaders::lookupJoint;

using nlohmann::json;
using namespace jsonread;

// ----- name look-ups ---------------------------------------------------------------------

/// Relative angle phi_j - phi_i of a joint's two points in the initial positions.
double initialJointAngle(const System& sys, ConstraintIndex joint) {
  const auto& c = dynamic_cast<const TwoPointConstraint&>(sys.constraint(joint));
  const Body& bi = sys.body(c.bodies()[0]);
  const Body& bj = sys.body(c.bodies()[1]);
  return bj.pointKinematics(bj.initialCoordinates(), c.pointJ()).phi -
         bi.pointKinematics(bi.initialCoordinates(), c.pointI()).phi;
}

// ----- bodies ----------------------------------------------------------------------------

/// Adds the planar flexible body `make()` with the initial elastic state of keys
/// "elastic_coordinates" and "elastic_velocities" (default zero; `nf` numbers each).
template <class MakeBody>
void addFlexibleBody(const ObjectReader& r, int nf, System& sys, MakeBody make) {
  const VecX q = scenereaders::readElasticState(r, "elastic_coordinates", nf);
  const VecX qDot = scenereaders::readElasticState(r, "elastic_velocities", nf);
  located(r.where(), [&] {
    std::unique_ptr<FfrBody2d> body = make();
    body->setInitialElasticState(q, qDot);
    return sys.addBody(std::move(body));
  });
}

FrameState2d parseFrameState(const ObjectReader& r) {
  FrameState2d init;
  init.position = r.vec2("position", Vec2::Zero());
  init.angle = r.number("angle", 0.0);
  init.velocity = r.vec2("velocity", Vec2::Zero());
  init.angularVelocity = r.number("angular_velocity", 0.0);
  return init;
}

BeamSection parseSection(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  r.allowOnly(scenekeys::kSection);
  BeamSection s;
  if (r.has("width") || r.has("height")) {
    if (r.has("area") || r.has("inertia")) r.fail("give either width and height, or area and inertia, not both");
    s = rectangularSection(r.positive("width"), r.positive("height"), 1.0, 1.0);
  } else {
    s.area = r.positive("area");
    s.inertia = r.positive("inertia");
  }
  s.youngsModulus = r.positive("youngs_modulus");
  s.density = r.positive("density");
  s.damping = r.nonNegative("damping", 0.0);
  // Timoshenko beams: G and kappa (a rectangle's default kappa: Cowper's, Cowper1966, with nu from E and G)
  if (r.has("shear_modulus")) s.shearModulus = r.positive("shear_modulus");
  if (r.has("shear_factor")) {
    s.shearFactor = r.positive("shear_factor");
  } else if (r.has("width") && s.shearModulus > 0.0) {
    s.shearFactor = rectangleShearFactor(s.youngsModulus, s.shearModulus);
  }
  return s;
}

void parseFlexibleBody(const ObjectReader& r, const std::string& name, System& sys) {
  r.allowOnly(scenekeys::kFlexibleBody, " for a flexible body");
  const BeamSection section = parseSection(r.object("section"), r.where() + ": section");
  BeamMesh2d mesh = scenereaders::readBeamMesh<BeamMesh2d>(r, {0, 0, section}, scenekeys::kBeam, "");
  FfrBeamOptions options;
  scenereaders::readBeamModelOptions(r, static_cast<int>(mesh.nodes.size()), options);
  const FrameState2d init = parseFrameState(r);
  const auto model = located(r.where(), [&] {
    return std::make_shared<const FfrBeamModel>(std::move(mesh), options, "body '" + name + "'");
  });
  addFlexibleBody(r, model->numElastic(), sys, [&] { return std::make_unique<FfrBody2d>(name, model, init); });
}

void parseInvariantBody(const ObjectReader& r, const std::string& name, System& sys) {
  r.allowOnly(scenekeys::kInvariantsBody, " for a flexible_invariants body");
  const ObjectReader iv(r.object("invariants"), r.where() + ": invariants");
  iv.allowOnly(scenekeys::kInvariants);
  FfrInvariants inv;
  inv.mass = iv.positive("mass");
  inv.firstMoment = iv.vec2("first_moment");
  inv.polarMoment = iv.positive("polar_moment");
  const MatX mff = iv.matrix("m_ff");
  const int nf = static_cast<int>(mff.rows());
  using scenereaders::readSquareInvariant;
  using scenereaders::sizedMatrix;
  inv.mff = readSquareInvariant(iv, "m_ff", nf);
  inv.sBar = scenereaders::readSizedMatrix(iv, "s_bar", 2, nf, nf);
  inv.i1 = sizedMatrix(iv, "i1", iv.vector("i1"), nf, 1, nf);
  inv.j0 = sizedMatrix(iv, "j0", iv.vector("j0"), nf, 1, nf);
  inv.sTilde = readSquareInvariant(iv, "s_tilde", nf);
  if (iv.has("r")) inv.rff = readSquareInvariant(iv, "r", nf);  // the sections' second-order rotation
  inv.kff = readSquareInvariant(iv, "k_ff", nf);
  inv.dff = readSquareInvariant(iv, "d_ff", nf, true);
  const json& pts = iv.array("points");
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const ObjectReader p(pts[k], iv.where() + ": points[" + std::to_string(k) + "]");
    p.allowOnly(scenekeys::kInvariantsPoint);
    FfrPoint fp;
    fp.position = p.vec2("position");
    const MatX shape = p.matrix("shape");  // checked before it goes into the 2-row N
    const VecX rotationShape = p.vector("rotation_shape");
    if (shape.rows() != 2 || shape.cols() != nf || rotationShape.size() != nf) {
      p.fail("\"shape\" must be 2 x " + std::to_string(nf) + " and \"rotation_shape\" " + std::to_string(nf) + " numbers");
    }
    fp.shape = shape;
    fp.rotationShape = rotationShape.transpose();
    inv.points.push_back(fp);
  }
  const FrameState2d init = parseFrameState(r);
  addFlexibleBody(r, nf, sys, [&] { return std::make_unique<FfrBody2d>(name, std::move(inv), init); });
}

/// A body of a planar scene written with spatial keys: the hint that the scene lacks
/// "dimension": 3 (otherwise the first key read says only that it is not planar).
void failIfWrittenAsSpatial(const ObjectReader& r) {
  std::string why;
  if (r.has("inertia") && r.required("inertia").is_array()) {
    why = "its \"inertia\" is a list (spatial: principal moments or a tensor)";
  } else if (r.has("angular_velocity") && r.required("angular_velocity").is_array()) {
    why = "its \"angular_velocity\" is a vector (planar: a number, rad/s)";
  } else {
    for (const char* key : {"position", "velocity"}) {
      if (why.empty() && r.has(key) && r.required(key).is_array() && r.required(key).size() == 3) {
        why = std::string("its \"") + key + "\" has 3 components";
      }
    }
    for (const char* key : {"orientation", "shape"}) {
      if (why.empty() && r.has(key)) why = std::string("it has the spatial key \"") + key + "\"";
    }
  }
  if (!why.empty()) {
    r.fail("this body looks spatial (" + why + ") but the scene is planar; give the scene \"dimension\": 3 "
           "(docs/scene-format.md, \"Spatial scenes\")");
  }
}

void parseBody(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  const auto [type, name] = scenereaders::readBodyTypeAndName(r);
  failIfWrittenAsSpatial(r);
  if (type == "flexible") return parseFlexibleBody(r, name, sys);
  if (type == "flexible_invariants") return parseInvariantBody(r, name, sys);
  if (type == "fe_body") r.fail("an fe_body (a solid FE mesh) is spatial: give the scene \"dimension\": 3");
  if (type == "sid_body") r.fail("a sid_body (a SID file's body) is spatial: give the scene \"dimension\": 3");
  r.allowOnly(scenekeys::kRigidBody, " for a rigid body");
  RigidBodyProperties props;
  props.mass = r.positive("mass");
  props.inertia = r.positive("inertia");
  props.com = r.vec2("com", Vec2::Zero());
  const FrameState2d init = parseFrameState(r);
  located(r.where(), [&] { return addRigidBody(sys, name, props, init); });
}

void parseJoint(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  if (scenereaders::readRegisteredComponent("joints", 2, r, sys)) return;
  std::vector<std::string> types = {"revolute", "prismatic", "fixed"};
  for (const std::string& t : scenereaders::registeredTypes("joints", 2)) types.push_back(t);
  const std::string type = readType(r, "joint", types);
  if (type != "prismatic" && r.has("axis")) {
    r.fail("key \"axis\" is only allowed for prismatic joints (this joint is " + type + ")");
  }
  if (type == "prismatic") {
    r.allowOnly(scenekeys::kPrismaticJoint, " for a prismatic joint");
  } else {
    r.allowOnly(scenekeys::kJoint, " for a " + type + " joint");
  }
  const std::string name = r.name("name");
  const auto [bi, bj] = lookupBodyPair(sys, r, "a joint");
  const auto points = r.pointPair("points");
  if (type == "revolute") {
    located(r.where(), [&] { return addRevoluteJoint(sys, name, bi, points[0], bj, points[1]); });
  } else if (type == "fixed") {
    located(r.where(), [&] { return addFixedJoint(sys, name, bi, points[0], bj, points[1]); });
  } else {
    const Vec2 axis = r.direction("axis", 2);
    located(r.where(), [&] { return addPrismaticJoint(sys, name, bi, points[0], bj, points[1], axis); });
  }
}

void parseDriver(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  const std::string type =
      readType(r, "driver", {"body_angle", "body_x", "body_y", "joint_angle", "joint_displacement"});
  const bool onJoint = type == "joint_angle" || type == "joint_displacement";
  r.allowOnly(onJoint ? scenekeys::kJointDriver : scenekeys::kBodyDriver, " for a " + type + " driver");
  const std::string name = r.name("name");
  if (onJoint) {
    const std::string jointName = r.name("joint");
    const ConstraintIndex joint = lookupJoint(sys, jointName, r);
    if (scenereaders::readDriverOfRegisteredJoint(type, name, joint, r, sys)) return;
    const std::string jointType = sys.constraint(joint).typeName();
    const std::string needed = type == "joint_angle" ? "revolute" : "prismatic";
    if (jointType != needed) {
      r.fail("a " + type + " driver needs a " + needed + " joint, but joint " + inQuotes(jointName) + " is " +
             jointType +
             (jointType == "prismatic" ? " (use a joint_displacement driver)"
              : jointType == "revolute" ? " (use a joint_angle driver)"
                                        : " (it has no free motion to drive)"));
    }
    TimeLawPtr law = parseTimeLaw(r.object("law"), r.where() + ".law");
    located(r.where(), [&] { return addJointDriver(sys, name, joint, law); });
  } else {
    const BodyIndex body = lookupBody(sys, r.name("body"), r);
    const std::string coordinate = type == "body_angle" ? "theta" : type == "body_x" ? "x" : "y";
    TimeLawPtr law = parseTimeLaw(r.object("law"), r.where() + ".law");
    located(r.where(), [&] { return addBodyCoordinateDriver(sys, name, body, coordinate, law); });
  }
}

void parseForce(const json& j, const std::string& where, System& sys) {
  ObjectReader r(j, where);
  r.peekName();
  const std::string type = readType(r, "force", {"spring_damper", "rotational_spring_damper", "applied_load"});
  const std::string forA = " for a " + type + " force";
  if (type == "spring_damper") {
    r.allowOnly(scenekeys::kSpringDamper, forA);
    const std::string name = r.name("name");
    const auto [bi, bj] = lookupBodyPair(sys, r, "a spring");
    const auto points = r.pointPair("points");
    const scenereaders::SpringDamperLaw law = scenereaders::readSpringDamperLaw(r, [&] {
      const Body& a = sys.body(bi);
      const Body& b = sys.body(bj);
      return (b.pointKinematics(b.initialCoordinates(), points[1]).r -
              a.pointKinematics(a.initialCoordinates(), points[0]).r).norm();
    });
    located(r.where(), [&] {
      return addSpringDamper(sys, name, bi, points[0], bj, points[1], law.stiffness, law.damping, law.freeLength);
    });
  } else if (type == "rotational_spring_damper") {
    r.allowOnly(scenekeys::kRotationalSpringDamper, forA);
    const std::string name = r.name("name");
    const std::string jointName = r.name("joint");
    const ConstraintIndex joint = lookupJoint(sys, jointName, r);
    const std::string jointType = sys.constraint(joint).typeName();
    if (jointType != "revolute") {
      r.fail("a rotational_spring_damper needs a revolute joint, but joint " + inQuotes(jointName) + " is " + jointType);
    }
    const double stiffness = r.nonNegative("stiffness");
    const double damping = r.nonNegative("damping", 0.0);
    const double freeAngle = r.has("free_angle") ? r.number("free_angle")
                                                 : located(r.where(), [&] { return initialJointAngle(sys, joint); });
    located(r.where(), [&] { return addRotationalSpringDamper(sys, name, joint, stiffness, damping, freeAngle); });
  } else {
    r.allowOnly(scenekeys::kAppliedLoad, forA);
    const std::string name = r.name("name");
    const BodyIndex body = lookupBody(sys, r.name("body"), r);
    const Vec2 point = r.vec2("point", Vec2::Zero());
    if (!r.has("force_x") && !r.has("force_y") && !r.has("torque")) {
      r.fail("an applied_load needs at least one of the keys \"force_x\", \"force_y\", \"torque\" (each a law object)");
    }
    TimeLawPtr fx, fy, tau;
    if (r.has("force_x")) fx = parseTimeLaw(r.object("force_x"), r.where() + ".force_x");
    if (r.has("force_y")) fy = parseTimeLaw(r.object("force_y"), r.where() + ".force_y");
    if (r.has("torque")) tau = parseTimeLaw(r.object("torque"), r.where() + ".torque");
    located(r.where(), [&] { return addAppliedLoad(sys, name, body, point, fx, fy, tau); });
  }
}


SolverSettings parseSolver(const json& j) {
  ObjectReader r(j, "solver");
  r.allowOnly(scenekeys::kSolver);
  SolverSettings s;
  if (r.has("integrator")) {
    const std::string name = r.string("integrator");
    try {
      s.integrator = parseIntegrator(name);
    } catch (const InputError&) {
      r.fail("unknown integrator " + inQuotes(name) + " (expected one of: auto, ida, radau, radau5, ali3p)");
    }
  }
  if (r.has("formulation")) {
    const std::string f = r.string("formulation");
    try {
      s.formulation = parseFormulation(f);
    } catch (const InputError&) {
      r.fail("unknown formulation " + inQuotes(f) + " (expected one of: ggl, index3, index1)");
    }
  }
  if (r.has("elastic_start")) {
    const std::string e = r.string("elastic_start");
    try {
      s.elasticStart = parseElasticStart(e);
    } catch (const InputError&) {
      r.fail("unknown elastic start " + inQuotes(e) + " (expected one of: given, quasi_static)");
    }
  }
  if (r.has("redundant_constraints")) {
    const std::string e = r.string("redundant_constraints");
    try {
      s.redundantConstraints = parseRedundantConstraints(e);
    } catch (const InputError&) {
      r.fail("unknown choice " + inQuotes(e) + " (expected one of: resolve, refuse)");
    }
  }
  if (r.has("quasi_static_above")) s.quasiStaticAbove = r.number("quasi_static_above");
  if (r.has("linear_solver")) {
    const std::string ls = r.string("linear_solver");
    try {
      s.linearSolver = parseLinearSolver(ls);
    } catch (const InputError&) {
      r.fail("unknown linear solver " + inQuotes(ls) + " (expected one of: auto, dense, klu)");
    }
  }
  s.rtol = r.number("rtol", s.rtol);
  s.atol = r.number("atol", s.atol);
  if (r.has("atol_velocity")) s.atolVelocity = r.number("atol_velocity");
  if (r.has("atol_angle")) s.atolAngle = r.number("atol_angle");
  if (r.has("atol_elastic")) s.atolElastic = r.number("atol_elastic");
  s.tStart = r.number("t_start", s.tStart);
  s.tEnd = r.number("t_end", s.tEnd);
  s.outputStep = r.number("output_step", s.outputStep);
  s.maxStepSize = r.number("max_step", s.maxStepSize);
  if (r.has("min_step")) s.minStepSize = r.number("min_step", 0.0);
  s.maxSteps = r.integer("max_steps", s.maxSteps, 1);
  s.maxTotalSteps = r.integer("max_total_steps", s.maxTotalSteps, 1);
  s.maxOrder = static_cast<int>(r.integer("max_order", s.maxOrder, 1));
  s.initialStepSize = r.number("initial_step", s.initialStepSize);
  s.finiteDifferenceJacobian = r.boolean("fd_jacobian", s.finiteDifferenceJacobian);
  s.crossSingular = r.boolean("cross_singular", s.crossSingular);
  checkSolverSettings(s);
  return s;
}

// ----- JSON text -----------------------------------------------------------------------------

/// Follows the parser through the document so that a number overflow or a duplicate
/// key can be reported with its location (nlohmann only gives a byte position).
class PathTracker {
 public:
  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        countElement();
        stack_.push_back(Frame{event == json::parse_event_t::array_start, "", -1, {}});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack_.empty()) stack_.pop_back();
        break;
      case json::parse_event_t::key:
        if (!stack_.empty()) {
          Frame& f = stack_.back();
          f.key = parsed.get<std::string>();
          if (!f.keys.insert(f.key).second) {
            throw InputError(path(false) + ": duplicate key " + inQuotes(f.key) + " (each key may appear once)");
          }
        }
        break;
      case json::parse_event_t::value:
        countElement();
        break;
    }
    return true;
  }

  /// Location of the value being parsed; pendingScalar: the parser failed on a scalar
  /// that has not been reported as a value yet.
  std::string path(bool pendingScalar) const {
    std::string p;
    for (std::size_t k = 0; k < stack_.size(); ++k) {
      const Frame& f = stack_[k];
      if (f.array) {
        const long index = f.index + ((pendingScalar && k + 1 == stack_.size()) ? 1 : 0);
        p += "[" + std::to_string(index) + "]";
      } else if (!f.key.empty()) {
        p += (p.empty() ? "" : ".") + f.key;
      }
    }
    return p.empty() ? "top level" : p;
  }

 private:
  struct Frame {
    bool array;
    std::string key;
    long index;
    std::set<std::string> keys;
  };
  void countElement() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().index;
  }
  std::vector<Frame> stack_;
};

}  // namespace

/// The node and stress shape of a "stress" output on `out.body`.
void readStressOutput(const ObjectReader& r, const std::vector<FeBodyDrawing>& feBodies, OutputRequest& out) {
  const FeBodyDrawing* fe = nullptr;
  for (const FeBodyDrawing& d : feBodies) {
    if (d.body == out.body) fe = &d;
  }
  if (!fe || fe->stressShapes.size() == 0) {
    r.fail("body " + inQuotes(out.bodyName) + (fe ? " has no \"stresses\"" : " is not an fe_body") +
           "; a stress output needs an fe_body with the key \"stresses\"");
  }
  if (!r.has("node")) r.fail("missing required key \"node\" (the FE code's node number)");
  out.node = static_cast<int>(r.integer("node", 0, std::numeric_limits<int>::min()));
  const auto it = std::find(fe->nodeIds.begin(), fe->nodeIds.end(), out.node);
  if (it == fe->nodeIds.end()) {
    r.fail("key \"node\": body " + inQuotes(out.bodyName) + " has no node " + std::to_string(out.node));
  }
  out.spatial = true;
  out.stressShape = fe->stressShapes.middleRows(6 * (it - fe->nodeIds.begin()), 6);
}

// ----- public API ------------------------------------------------------------------------------

namespace {

/// A point output farther from its body's frame than kMaxMagnitudeRatio times the model's
/// size is a typo (z = -1e100), not a point of the body: its coordinates would be the
/// round-off of the body's motion times 1e100.
void checkOutputPointSize(const ObjectReader& r, const Vec3& p, const System& sys) {
  const double L = sys.characteristicLength();
  if (!(p.norm() <= kMaxMagnitudeRatio * L)) {
    r.fail("point " + vectorText(p) + " is " + fmt(p.norm() / L) + " times the model's size (" + fmt(L) +
           " m), more than " + fmt(kMaxMagnitudeRatio) + ": expected a point of the body (body frame, m)");
  }
}

}  // namespace

OutputRequest parseOutputRequest(const json& j, const std::string& where, const System& sys,
                                 const std::vector<OutputRequest>& earlier, bool spatial,
                                 const std::vector<FeBodyDrawing>& feBodies) {
  ObjectReader r(j, where);
  r.peekName();
  const std::string type = readType(r, "output", {"point", "energy", "deflection", "stress"});
  OutputRequest out;
  if (type == "energy") {
    r.allowOnly(scenekeys::kEnergyOutput, " for an energy output");
    for (const auto& o : earlier) {
      if (o.type == OutputRequest::Type::Energy) r.fail("the energy output is requested twice");
    }
    out.type = OutputRequest::Type::Energy;
    return out;
  }
  r.allowOnly(type == "stress" ? scenekeys::kStressOutput : scenekeys::kPointOutput, " for a " + type + " output");
  out.type = type == "point"    ? OutputRequest::Type::Point
             : type == "stress" ? OutputRequest::Type::Stress
                                : OutputRequest::Type::Deflection;
  out.name = r.name("name");
  // Column names must stay unique: "<name>.x" may not clash with "<body>.x" or
  // "<joint>.fx" or with another output's columns.
  if (out.name == "energy") r.fail("the name \"energy\" is reserved for the energy output columns");
  for (int i = 0; i < sys.numBodies(); ++i) {
    if (sys.body(BodyIndex(i)).name() == out.name) {
      r.fail("name " + inQuotes(out.name) + " is already used by a body; give the output its own name");
    }
  }
  for (int i = 0; i < sys.numConstraints(); ++i) {
    if (sys.constraint(ConstraintIndex(i)).name() == out.name) {
      r.fail("name " + inQuotes(out.name) + " is already used by a joint or driver; give the output its own name");
    }
  }
  for (const auto& o : earlier) {
    if (o.type != OutputRequest::Type::Energy && o.name == out.name) {
      r.fail("duplicate output name " + inQuotes(out.name));
    }
  }
  out.bodyName = r.name("body");
  out.body = lookupBody(sys, out.bodyName, r);
  if (out.type == OutputRequest::Type::Stress) {
    readStressOutput(r, feBodies, out);
    return out;
  }
  if (spatial) {
    out.spatial = true;
    out.point3 = r.has("point") ? Vec3(r.vector("point", 3)) : Vec3::Zero();
    if (out.type == OutputRequest::Type::Deflection) {
      const auto* fb = dynamic_cast<const FfrBody3d*>(&sys.body(out.body));
      if (!fb || !fb->model()) {
        r.fail("body " + inQuotes(out.bodyName) + " is not a flexible body made from a beam mesh; a deflection output needs one");
      }
      if (!fb->model()->locate(out.point3, out.element, out.xi)) {
        r.fail("point [" + fmt(out.point3.x()) + ", " + fmt(out.point3.y()) + ", " + fmt(out.point3.z()) +
               "] is not on the axis of any element of body " + inQuotes(out.bodyName) + " (undeformed, body frame)");
      }
      return out;
    }
    checkOutputPointSize(r, out.point3, sys);
    located(r.where(), [&] { out.pointId = sys.body(out.body).resolvePoint(out.point3, "output " + inQuotes(out.name)); });
    return out;
  }
  out.point = r.vec2("point", Vec2::Zero());
  checkOutputPointSize(r, lift(out.point), sys);
  if (out.type == OutputRequest::Type::Deflection) {
    const auto* fb = dynamic_cast<const FfrBody2d*>(&sys.body(out.body));
    if (!fb || !fb->beamModel()) {
      r.fail("body " + inQuotes(out.bodyName) + " is not a flexible body made from a beam mesh; a deflection output needs one");
    }
    if (!fb->beamModel()->locate(out.point, out.element, out.xi)) {
      r.fail("point [" + fmt(out.point.x()) + ", " + fmt(out.point.y()) + "] is not on the axis of any element of body " +
             inQuotes(out.bodyName) + " (undeformed, body frame)");
    }
    return out;
  }
  located(r.where(), [&] { out.pointId = sys.body(out.body).resolvePoint(lift(out.point), "output " + inQuotes(out.name)); });
  return out;
}

std::vector<std::string> OutputRequest::columnNames() const {
  if (type == Type::Energy) return {"energy.kinetic", "energy.potential", "energy.total"};
  if (type == Type::Stress) {
    return {name + ".sxx", name + ".syy", name + ".szz", name + ".sxy", name + ".syz", name + ".szx", name + ".von_mises"};
  }
  if (type == Type::Deflection && spatial) {
    return {name + ".ux", name + ".uy", name + ".uz", name + ".N",  name + ".Qy",
            name + ".Qz", name + ".Mx", name + ".My", name + ".Mz"};
  }
  if (type == Type::Deflection) return {name + ".ux", name + ".uy", name + ".N", name + ".M"};
  if (spatial) return {name + ".x", name + ".y", name + ".z", name + ".vx", name + ".vy", name + ".vz"};
  return {name + ".x", name + ".y", name + ".vx", name + ".vy"};
}

std::vector<double> OutputRequest::evaluate(const System& sys, const VecX& q, const VecX& v) const {
  if (type == Type::Energy) {
    const double kinetic = kineticEnergy(sys, q, v);
    const double potential = potentialEnergy(sys, q);
    return {kinetic, potential, kinetic + potential};
  }
  const Body& b = sys.body(body);
  const int off = sys.coordinateOffset(body);
  if (type == Type::Stress) {  // sigma = S q_f, the elastic coordinates after R and p
    const int nf = static_cast<int>(stressShape.cols());
    const Eigen::Matrix<double, 6, 1> sg = stressShape * q.segment(off + 7, nf);
    return {sg[0], sg[1], sg[2], sg[3], sg[4], sg[5], vonMises(sg)};
  }
  if (spatial && type == Type::Deflection) {
    const FfrBody3d::BeamDeflection d =
        static_cast<const FfrBody3d&>(b).beamDeflection(q.segment(off, b.numCoordinates()), element, xi);
    const BeamSectionForces3d& f = d.sectionForces;
    return {d.displacement.x(), d.displacement.y(), d.displacement.z(), f.N, f.Qy, f.Qz, f.Mx, f.My, f.Mz};
  }
  if (spatial) {
    FrameKinematics f;
    b.frameKinematics(q.segment(off, b.numCoordinates()), point3, pointId, nullptr, nullptr, f);
    const Vec3 vel = f.Jr * v.segment(sys.velocityOffset(body), b.numVelocities());
    return {f.r.x(), f.r.y(), f.r.z(), vel.x(), vel.y(), vel.z()};
  }
  if (type == Type::Deflection) {
    const FfrBody2d::BeamDeflection d =
        static_cast<const FfrBody2d&>(b).beamDeflection(q.segment(off, b.numCoordinates()), element, xi);
    return {d.displacement.x(), d.displacement.y(), d.sectionForces.x(), d.sectionForces.y()};
  }
  const int n = b.numCoordinates();
  PointKinematics pk;
  b.pointKinematics(q.segment(off, n), point, pointId, nullptr, false, pk);
  const Vec2 vel = n > 0 ? Vec2(pk.Jr * v.segment(off, n)) : Vec2::Zero();
  return {pk.r.x(), pk.r.y(), vel.x(), vel.y()};
}

void checkSolverSettings(const SolverSettings& s) {
  const auto fail = [](const std::string& m) { throw InputError("solver: " + m); };
  const auto positive = [&](double x, const char* key) {
    if (!std::isfinite(x)) fail(std::string("key \"") + key + "\" must be a finite number, got " + fmt(x));
    if (!(x > 0.0)) fail(std::string("key \"") + key + "\" must be > 0, got " + fmt(x));
  };
  positive(s.rtol, "rtol");
  positive(s.atol, "atol");
  if (s.atolVelocity) positive(*s.atolVelocity, "atol_velocity");
  if (!std::isfinite(s.tStart)) fail("key \"t_start\" must be a finite number, got " + fmt(s.tStart));
  if (!std::isfinite(s.tEnd)) fail("key \"t_end\" must be a finite number, got " + fmt(s.tEnd));
  if (!(s.tEnd > s.tStart)) {
    fail("key \"t_end\" must be > t_start (" + fmt(s.tStart) + "), got " + fmt(s.tEnd));
  }
  positive(s.outputStep, "output_step");
  if (!std::isfinite(s.maxStepSize) || s.maxStepSize < 0.0) {
    fail("key \"max_step\" must be >= 0 (0: no limit), got " + fmt(s.maxStepSize));
  }
  if (s.maxSteps < 1) fail("key \"max_steps\" must be >= 1, got " + std::to_string(s.maxSteps));
  try {
    s.validate();
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.rfind("solver", 0) == 0) throw;
    fail(m);
  }
}

namespace {

/// A list of non-empty strings under `key` of `r` (absent: empty).
std::vector<std::string> nonEmptyStrings(const ObjectReader& r, const std::string& key, const std::string& what) {
  std::vector<std::string> out;
  const json& a = r.array(key);
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (!a[k].is_string() || a[k].get<std::string>().empty()) {
      r.fail("key \"" + key + "\": element [" + std::to_string(k) + "] must be " + what + ", got " + describe(a[k]));
    }
    out.push_back(a[k].get<std::string>());
  }
  return out;
}

/// The "sensitivity" object: the parameters (paths checked against the scene by
/// buildSensitivityScenes), the adjoint outputs (checked by integralOutput), error control.
SensitivityRequest parseSensitivityRequest(const json& j) {
  ObjectReader r(j, "sensitivity");
  r.allowOnly(scenekeys::kSensitivity);
  SensitivityRequest s;
  s.parameters = nonEmptyStrings(r, "parameters", "a dotted scene path (e.g. \"bodies[1].mass\")");
  s.adjoint = nonEmptyStrings(r, "adjoint", "an adjoint output KIND:COLUMN (e.g. \"integral_square:mid.uy\")");
  s.errorControl = r.boolean("error_control", true);
  if (s.parameters.empty()) r.fail("key \"parameters\" must list at least one dotted scene path");
  if (!s.adjoint.empty() && !s.errorControl) {
    r.fail("key \"error_control\" is for the forward sensitivities: false is not allowed with \"adjoint\"");
  }
  return s;
}

}  // namespace

Scene parseScene(const json& j, const std::string& baseDir) {
  ObjectReader top(j, "top level");
  top.allowOnly(scenekeys::kScene);
  Scene scene;
  scene.name = top.string("name", "");
  System& sys = scene.system;

  // "dimension": 2 (planar, the default) or 3 (spatial): which readers the objects go to
  const bool spatial = top.integer("dimension", 2, 2, 3) == 3;
  if (!top.has("bodies")) top.fail("missing required key \"bodies\"");
  const json& bodies = top.array("bodies");
  if (bodies.empty()) top.fail("key \"bodies\" must list at least one body");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::string at = "bodies[" + std::to_string(i) + "]";
    spatial ? scenereaders::parseSpatialBody(bodies[i], at, sys, baseDir, &scene.feBodies) : parseBody(bodies[i], at, sys);
    if (bodies[i].contains("geometry")) {  // a rigid body's (the readers refuse the key elsewhere)
      const BodyIndex b(sys.numBodies() - 1);
      scene.geometry.push_back({b, scenereaders::parseGeometry(bodies[i]["geometry"],
                                                               at + " (\"" + sys.body(b).name() + "\").geometry")});
    }
  }

  const json& joints = top.array("joints");
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const std::string at = "joints[" + std::to_string(i) + "]";
    spatial ? scenereaders::parseSpatialJoint(joints[i], at, sys) : parseJoint(joints[i], at, sys);
  }

  const json& drivers = top.array("drivers");
  for (std::size_t i = 0; i < drivers.size(); ++i) {
    const std::string at = "drivers[" + std::to_string(i) + "]";
    spatial ? scenereaders::parseSpatialDriver(drivers[i], at, sys) : parseDriver(drivers[i], at, sys);
  }

  const json& forces = top.array("forces");
  for (std::size_t i = 0; i < forces.size(); ++i) {
    const std::string at = "forces[" + std::to_string(i) + "]";
    spatial ? scenereaders::parseSpatialForce(forces[i], at, sys) : parseForce(forces[i], at, sys);
  }

  if (spatial) {
    const Vec3 g = top.has("gravity") ? Vec3(top.vector("gravity", 3)) : Vec3::Zero();
    located("top level", [&] { sys.setGravity(g); });
  } else {
    const Vec2 g = top.vec2("gravity", Vec2::Zero());
    located("top level", [&] { sys.setGravity(g); });
  }

  const json& outputs = top.array("outputs");
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    scene.outputs.push_back(
        parseOutputRequest(outputs[i], "outputs[" + std::to_string(i) + "]", sys, scene.outputs, spatial, scene.feBodies));
  }

  scene.solver = top.has("solver") ? parseSolver(top.object("solver")) : SolverSettings{};
  if (!top.has("solver")) checkSolverSettings(scene.solver);
  if (top.has("sensitivity")) scene.sensitivity = parseSensitivityRequest(top.object("sensitivity"));

  located("scene", [&] { sys.finalize(); });
  return scene;
}

Scene parseSceneText(const std::string& text, const std::string& source) {
  checkJsonNesting(text, source);
  PathTracker tracker;
  json j;
  try {
    j = json::parse(text, std::ref(tracker), /*allow_exceptions=*/true);
  } catch (const json::parse_error& e) {
    throw InputError(source + ": invalid JSON at byte " + std::to_string(e.byte) + ": " + plainMessage(e));
  } catch (const json::out_of_range& e) {
    // 406: a number literal that does not fit a double (1e999).
    throw InputError(source + ": " + tracker.path(true) + ": " + plainMessage(e) +
                     " (the number is too large for a double; numbers must be finite)");
  } catch (const json::exception& e) {
    throw InputError(source + ": invalid JSON: " + plainMessage(e));
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  checkSceneKind(j, SceneKind::Multibody, source);
  try {
    // files a scene names (an fe_body's exports) are relative to the scene file's folder
    return parseScene(j, std::filesystem::path(source).parent_path().string());
  } catch (const ModelError& e) {
    throw ModelError(source + ": " + e.what());
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

Scene loadScene(const std::string& path) { return parseSceneText(readSceneFile(path), path); }

}  // namespace flexmbd
