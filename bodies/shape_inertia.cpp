#include "bodies/shape_inertia.hpp"

#include <cmath>
#include <string>

#include "core/errors.hpp"

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
      // solid cuboid: Ixx = m (b^2 + c^2) / 12, ... (e.g. Meriam & Kraige, Dynamics, table D/4)
      I << m * (e2[1] + e2[2]) / 12.0, m * (e2[0] + e2[2]) / 12.0, m * (e2[0] + e2[1]) / 12.0;
      break;
    }
    case SolidShape::Type::Cylinder:
    case SolidShape::Type::Tube: {
      // tube (ri = 0: solid cylinder): axial m (ri^2 + ro^2) / 2, transverse m (3 (ri^2 + ro^2) + h^2) / 12
      const double sum2 = r2 + ri2;
      I.setConstant(m * (3.0 * sum2 + h2) / 12.0);
      I[s.axis] = m * sum2 / 2.0;
      break;
    }
    case SolidShape::Type::Sphere:
      I.setConstant(0.4 * m * r2);  // solid sphere: 2/5 m r^2
      break;
  }
  return I.asDiagonal();
}

RigidBody3dProperties shapeProperties(const SolidShape& s, double mass, double density) {
  RigidBody3dProperties p;
  p.mass = mass > 0.0 ? mass : density * shapeVolume(s);
  p.inertia = shapeInertia(s, p.mass);
  return p;
}

}  // namespace flexmbd
