#include "elements/beam_section.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/errors.hpp"
#include "core/types.hpp"

namespace flexmbd {

void BeamSection::validate(const std::string& owner) const {
  requirePositive(area, owner + ": section area");
  requirePositive(inertia, owner + ": section inertia (second moment of area)");
  requirePositive(youngsModulus, owner + ": section youngs_modulus");
  requirePositive(density, owner + ": section density");
  requireNonNegative(damping, owner + ": section damping");
  requireNonNegative(shearModulus, owner + ": section shear_modulus");
  requireNonNegative(shearFactor, owner + ": section shear_factor");
}

BeamSection rectangularSection(double width, double height, double youngsModulus, double density,
                               double damping) {
  BeamSection s;
  s.area = width * height;
  s.inertia = width * height * height * height / 12.0;
  s.youngsModulus = youngsModulus;
  s.density = density;
  s.damping = damping;
  return s;
}

void BeamSection3d::validate(const std::string& owner) const {
  requirePositive(area, owner + ": section area");
  requirePositive(inertiaY, owner + ": section inertia_y (second moment int z^2 dA)");
  requirePositive(inertiaZ, owner + ": section inertia_z (second moment int y^2 dA)");
  requirePositive(torsionConstant, owner + ": section torsion_constant");
  requirePositive(youngsModulus, owner + ": section youngs_modulus");
  requirePositive(shearModulus, owner + ": section shear_modulus");
  requirePositive(density, owner + ": section density");
  requireNonNegative(damping, owner + ": section damping");
  requireNonNegative(shearFactorY, owner + ": section shear_factor_y");
  requireNonNegative(shearFactorZ, owner + ": section shear_factor_z");
}

BeamShear BeamSection3d::shearFlexibility(double l, const std::string& owner) const {
  for (const auto& [kappa, key] : {std::pair<double, const char*>{shearFactorY, "shear_factor_y"},
                                   std::pair<double, const char*>{shearFactorZ, "shear_factor_z"}}) {
    if (!(kappa > 0.0)) {
      std::ostringstream os;
      os << owner << ": a Timoshenko beam needs the section's " << key
         << " (shear correction factor, e.g. 5/6 for a rectangle), got " << kappa;
      throw InputError(os.str());
    }
  }
  const double gal2 = shearModulus * area * l * l;
  // phi = 12 E I / (kappa G A l^2) (Przemieniecki1968, sec. 5.6)
  return {12.0 * bendingStiffnessZ() / (shearFactorY * gal2), 12.0 * bendingStiffnessY() / (shearFactorZ * gal2)};
}

double rectangleShearFactor(double youngsModulus, double shearModulus) {
  // isotropic: G = E / (2 (1 + nu)) (TimoshenkoGoodier1970)
  const double nu = youngsModulus / (2.0 * shearModulus) - 1.0;
  return 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);                 // Cowper1966, table 1
}

double circleShearFactor(double youngsModulus, double shearModulus) {
  const double nu = youngsModulus / (2.0 * shearModulus) - 1.0;
  return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);  // Cowper1966, table 1
}

BeamSection3d rectangularSection3d(double widthY, double heightZ, double youngsModulus, double shearModulus,
                                   double density, double damping) {
  constexpr double pi = 3.14159265358979323846;
  BeamSection3d s;
  s.area = widthY * heightZ;
  s.inertiaY = widthY * heightZ * heightZ * heightZ / 12.0;  // int z^2 dA = b h^3 / 12
  s.inertiaZ = heightZ * widthY * widthY * widthY / 12.0;    // int y^2 dA = h b^3 / 12
  // St Venant torsion of a rectangle, exact series (TimoshenkoGoodier1970, sec. 109):
  // J = (a b^3/3) [1 - (192/pi^5)(b/a) sum_{n odd} tanh(n pi a/(2b)) / n^5], a >= b
  const double a = std::max(std::abs(widthY), std::abs(heightZ));
  const double b = std::min(std::abs(widthY), std::abs(heightZ));
  double sum = 0.0;
  if (b > 0.0) {
    for (int n = 1; n <= 101; n += 2) sum += std::tanh(n * pi * a / (2.0 * b)) / std::pow(n, 5);
    s.torsionConstant = a * b * b * b / 3.0 * (1.0 - 192.0 / std::pow(pi, 5) * (b / a) * sum);
  }
  s.youngsModulus = youngsModulus;
  s.shearModulus = shearModulus;
  s.density = density;
  s.damping = damping;
  s.shearFactorY = s.shearFactorZ = rectangleShearFactor(youngsModulus, shearModulus);
  return s;
}

BeamSection3d circularSection3d(double diameter, double youngsModulus, double shearModulus, double density,
                                double damping) {
  constexpr double pi = 3.14159265358979323846;
  const double d2 = diameter * diameter;
  BeamSection3d s;
  s.area = pi * d2 / 4.0;                    // A = pi d^2 / 4
  s.inertiaY = s.inertiaZ = pi * d2 * d2 / 64.0;  // I = pi d^4 / 64
  s.torsionConstant = pi * d2 * d2 / 32.0;   // J = Ip = pi d^4 / 32 (no warping; TimoshenkoGoodier1970)
  s.youngsModulus = youngsModulus;
  s.shearModulus = shearModulus;
  s.density = density;
  s.damping = damping;
  s.shearFactorY = s.shearFactorZ = circleShearFactor(youngsModulus, shearModulus);
  return s;
}

}  // namespace flexmbd
