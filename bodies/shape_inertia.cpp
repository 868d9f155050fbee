#include "bodies/shape_inertia.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {
namespace {

void requirePositive(double x, const char* what) {
  if (!std::isfinite(x) || !(x > 0.0)) {
    throw InputError(std::string("shape: ") + what + " must be a finite number > 0, got " + std::to_string(x));
  }
}

void checkDimensions(const SolidShape& s) {
  switch (s.type) {
    case SolidShape::Type::Box:
      for (int k = 0; k < 3; ++k) requirePositive(s.size[k], "size");
      return;
    case SolidShape::Type::Tube:
      if (!std::isfinite(s.innerRadius) || s.innerRadius < 0.0 || !(s.innerRadius < s.radius)) {
        throw InputError("shape: inner_radius must be >= 0 and < outer_radius, got " + std::to_string(s.innerRadius) +
                         " and " + std::to_string(s.radius));
      }
      [[fallthrough]];
    case SolidShape::Type::Cylinder:
      requirePositive(s.length, "length");
      if (s.axis < 0 || s.axis > 2) throw InputError("shape: axis must be 0, 1 or 2 (x, y or z)");
      [[fallthrough]];
    case SolidShape::Type::Sphere:
      requirePositive(s.radius, "radius");
      return;
  }
}

}  // namespace

double shapeVolume(const SolidShape& s) {
  checkDimensions(s);
  const double r2 = s.radius * s.radius, ri2 = s.innerRadius * s.innerRadius;
  switch (s.type) {
    case SolidShape::Type::Box: return s.size.prod();                            // a b c
    case SolidShape::Type::Cylinder: return M_PI * r2 * s.length;                // pi r^2 h
    case SolidShape::Type::Tube: return M_PI * (r2 - ri2) * s.length;            // pi (ro^2 - ri^2) h
    case SolidShape::Type::Sphere: return 4.0 / 3.0 * M_PI * r2 * s.radius;      // 4/3 pi r^3
  }
  return 0.0;
}

Mat3 shapeInertia(const SolidShape& s, double m) {
  checkDimensions(s);
  requirePositive(m, "mass");
  Vec3 I = Vec3::Zero();
  const double r2 = s.radius * s.radius, ri2 = s.innerRadius * s.innerRadius, h2 = s.length * s.length;
  switch (s.type) {
    case SolidShape::Type::Box: {
      const Vec3 e2 = s.size.cwiseAbs2();
      // solid cuboid: Ixx = m (b^2 + c^2) / 12, ... (e.g. MeriamKraige, table D/4)
      I << m * (e2[1] + e2[2]) / 12.0, m * (e2[0] + e2[2]) / 12.0, m * (e2[0] + e2[1]) / 12.0;
      break;
    }
    case SolidShape::Type::Cylinder:
    case SolidShape::Type::Tube: {
      // tube (ri = 0: solid cylinder): axial m (ri^2 + ro^2) / 2, transverse m (3 (ri^2 + ro^2) + h^2) / 12
      // (a solid cylinder less its bore: MeriamKraige, table D/4)
      const double sum2 = r2 + ri2;
      I.setConstant(m * (3.0 * sum2 + h2) / 12.0);
      I[s.axis] = m * sum2 / 2.0;
      break;
    }
    case SolidShape::Type::Sphere:
      I.setConstant(0.4 * m * r2);  // solid sphere: 2/5 m r^2 (MeriamKraige, table D/4)
      break;
  }
  return I.asDiagonal();
}

namespace {

std::string vectorText(const Vec3& v) { return "[" + fmt(v[0], 7) + ", " + fmt(v[1], 7) + ", " + fmt(v[2], 7) + "]"; }

/// Half the largest extent of the shape about its centre (m): a box's half-diagonal, a
/// cylinder's sqrt(r^2 + (h/2)^2), a sphere's radius.
double halfExtent(const SolidShape& s) {
  switch (s.type) {
    case SolidShape::Type::Box: return 0.5 * s.size.norm();
    case SolidShape::Type::Cylinder:
    case SolidShape::Type::Tube: return std::hypot(s.radius, 0.5 * s.length);
    case SolidShape::Type::Sphere: return s.radius;
  }
  return 0.0;
}

void checkOrientation(const SolidShape& s) {
  const Mat3& A = s.orientation;
  if (!A.allFinite() || !((A.transpose() * A - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) || !(A.determinant() > 0.0)) {
    throw InputError("shape: orientation is not a rotation (expected orthonormal, determinant +1, to 1e-9)");
  }
  if (!s.offset.allFinite()) throw InputError("shape: offset must be 3 finite numbers, got " + vectorText(s.offset));
}

}  // namespace

CompositeInertia compositeInertia(const std::vector<ShapePart>& parts) {
  if (parts.empty()) throw InputError("shapes: give at least one shape");
  CompositeInertia c;
  Mat3 aboutOrigin = Mat3::Zero();
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const ShapePart& p = parts[k];
    const SolidShape& s = p.shape;
    try {
      if ((p.mass > 0.0) == (p.density > 0.0)) throw InputError("shape: give exactly one of mass or density (> 0)");
      checkOrientation(s);
      const double m = p.mass > 0.0 ? p.mass : p.density * shapeVolume(s);
      const Mat3 Ic = s.orientation * shapeInertia(s, m) * s.orientation.transpose();  // I' = A I A^T
      const Vec3& d = s.offset;
      // parallel-axis theorem: I_O = I_c + m (|d|^2 E - d d^T) (MeriamKraige, eq. 7/10)
      aboutOrigin += Ic + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
      c.mass += m;
      c.centreOfMass += m * d;
    } catch (const InputError& e) {
      throw InputError(parts.size() == 1 ? std::string(e.what())
                                         : "shapes[" + std::to_string(k) + "]: " + std::string(e.what()));
    }
  }
  c.centreOfMass /= c.mass;
  const Vec3& g = c.centreOfMass;
  c.inertia = aboutOrigin - c.mass * (g.squaredNorm() * Mat3::Identity() - g * g.transpose());  // back to the centre
  c.inertia = 0.5 * (c.inertia + c.inertia.transpose());
  return c;
}

RigidBody3dProperties shapeProperties(const std::vector<ShapePart>& parts) {
  const CompositeInertia c = compositeInertia(parts);
  double extent = 0.0;
  for (const ShapePart& p : parts) extent = std::max(extent, p.shape.offset.norm() + halfExtent(p.shape));
  if (c.centreOfMass.norm() > kShapeCentreTolerance * extent) {
    throw InputError("shapes: their centre of mass is at " + vectorText(c.centreOfMass) +
                     " (body axes), but a body's frame origin is its centre of mass: subtract it from every offset "
                     "(and from the body's joint points), or add the shape that balances it");
  }
  RigidBody3dProperties props;
  props.mass = c.mass;
  props.inertia = c.inertia;
  return props;
}

RigidBody3dProperties shapeProperties(const SolidShape& s, double mass, double density) {
  return shapeProperties(std::vector<ShapePart>{{s, mass, density}});
}

}  // namespace flexmbd
