// Cross-section and material of a planar Euler-Bernoulli beam.
#pragma once

#include <string>

namespace flexmbd {

struct BeamSection {
  double area = 0.0;           ///< A, m^2
  double inertia = 0.0;        ///< second moment of area I, m^4
  double youngsModulus = 0.0;  ///< E, Pa
  double density = 0.0;        ///< rho, kg/m^3
  /// Stiffness-proportional (Rayleigh) damping coefficient beta, s: D = beta K.
  double damping = 0.0;

  double massPerLength() const { return density * area; }
  double axialStiffness() const { return youngsModulus * area; }
  double bendingStiffness() const { return youngsModulus * inertia; }
  /// @throws InputError naming `owner` unless A, I, E, rho > 0 and damping >= 0.
  void validate(const std::string& owner) const;
};

/// Rectangular b x h section (bending about the axis parallel to b).
BeamSection rectangularSection(double width, double height, double youngsModulus, double density,
                               double damping = 0.0);

}  // namespace flexmbd
