/// @file
/// Cross-sections and materials of Euler-Bernoulli beams: planar (BeamSection) and
/// spatial (BeamSection3d).
#pragma once

#include <string>

namespace flexmbd {

/// The beam theory of an element (docs/spatial-flexible.md):
/// Euler-Bernoulli keeps the centre line's inertia and the sections' rotation by the
/// twist; Rayleigh adds the rotary inertia of the sections turned by the bending slopes
/// (rho I int v'^2 dx: the gyroscopic moments of a spinning shaft). Both keep the
/// Euler-Bernoulli kinematics (sections normal to the centre line, no shear strain).
/// Timoshenko adds the shear strain gamma = v' - psi (sections turn by their own
/// rotation psi, energy kappa G A gamma^2 / 2 per length; Przemieniecki1968, sec. 5.6) and
/// the rotary inertia of psi.
enum class BeamTheory { EulerBernoulli, Rayleigh, Timoshenko };

/// Shear flexibility of a Timoshenko element per bending plane, phi = 12 E I /
/// (kappa G A l^2) (Przemieniecki1968, sec. 5.6):
/// `y` for the x-y plane (v, tz; E Iz, shear along y, kappa_y), `z` for the x-z plane
/// (w, ty; E Iy, kappa_z). Zero (Euler-Bernoulli, Rayleigh): the Hermite cubics.
struct BeamShear {
  double y = 0.0;
  double z = 0.0;
};

struct BeamSection {
  double area = 0.0;           ///< A, m^2
  double inertia = 0.0;        ///< second moment of area I, m^4
  double youngsModulus = 0.0;  ///< E, Pa
  double density = 0.0;        ///< rho, kg/m^3
  /// Stiffness-proportional (Rayleigh) damping coefficient beta, s: D = beta K (GeradinRixen).
  double damping = 0.0;
  /// Timoshenko only (BeamTheory::Timoshenko; 0 = not given): shear modulus G, Pa, and
  /// shear correction factor kappa (shear stiffness kappa G A).
  double shearModulus = 0.0;
  double shearFactor = 0.0;

  double massPerLength() const { return density * area; }
  double axialStiffness() const { return youngsModulus * area; }
  double bendingStiffness() const { return youngsModulus * inertia; }
  /// @throws InputError naming `owner` unless A, I, E, rho > 0, damping, G, kappa >= 0.
  void validate(const std::string& owner) const;
};

/// Rectangular b x h section (bending about the axis parallel to b).
BeamSection rectangularSection(double width, double height, double youngsModulus, double density,
                               double damping = 0.0);

/// Cross-section and material of a spatial Euler-Bernoulli beam (elements/beam_element_3d).
/// Section axes y, z: principal axes through the centroid (the element's y and z axes),
/// so int y dA = int z dA = int y z dA = 0.
struct BeamSection3d {
  double area = 0.0;             ///< A, m^2
  double inertiaY = 0.0;         ///< Iy = int z^2 dA, m^4: bending in the x-z plane
  double inertiaZ = 0.0;         ///< Iz = int y^2 dA, m^4: bending in the x-y plane
  double torsionConstant = 0.0;  ///< St Venant torsion constant J, m^4 (J = Ip for a circle only)
  double youngsModulus = 0.0;    ///< E, Pa
  double shearModulus = 0.0;     ///< G, Pa
  double density = 0.0;          ///< rho, kg/m^3
  /// Stiffness-proportional (Rayleigh) damping coefficient beta, s: D = beta K (GeradinRixen).
  double damping = 0.0;
  /// Shear correction factors (Timoshenko only; 0 = not given): shear stiffness
  /// kappa_y G A for shear along y (bending in x-y), kappa_z G A along z.
  double shearFactorY = 0.0;
  double shearFactorZ = 0.0;

  double massPerLength() const { return density * area; }         ///< rho A, kg/m
  double polarMoment() const { return inertiaY + inertiaZ; }      ///< Ip = int (y^2 + z^2) dA, m^4
  double axialStiffness() const { return youngsModulus * area; }  ///< EA, N
  double bendingStiffnessY() const { return youngsModulus * inertiaY; }  ///< E Iy, N m^2 (x-z plane)
  double bendingStiffnessZ() const { return youngsModulus * inertiaZ; }  ///< E Iz, N m^2 (x-y plane)
  double torsionStiffness() const { return shearModulus * torsionConstant; }  ///< G J, N m^2
  /// @throws InputError naming `owner` unless A, Iy, Iz, J, E, G, rho > 0 (and finite)
  /// and damping, kappa_y, kappa_z >= 0 (and finite).
  void validate(const std::string& owner) const;
  /// phi_y = 12 E Iz / (kappa_y G A l^2), phi_z = 12 E Iy / (kappa_z G A l^2) of an
  /// element of length l (Przemieniecki1968, sec. 5.6). @throws InputError naming `owner` unless
  /// both factors are > 0.
  BeamShear shearFlexibility(double l, const std::string& owner) const;
};

/// Cowper's shear correction factors (Cowper1966, table 1) with Poisson's ratio
/// nu = E / (2 G) - 1 of an isotropic material:
/// rectangle 10 (1 + nu) / (12 + 11 nu), solid circle 6 (1 + nu) / (7 + 6 nu).
double rectangleShearFactor(double youngsModulus, double shearModulus);
double circleShearFactor(double youngsModulus, double shearModulus);

/// Rectangular section, side `widthY` along the section's y axis and `heightZ` along z:
/// A = b h, Iz = h b^3 / 12, Iy = b h^3 / 12, and the St Venant torsion constant of the
/// rectangle by its exact series (TimoshenkoGoodier1970, sec. 109), with a >= b the longer
/// and shorter sides:
///   J = (a b^3 / 3) [1 - (192 / pi^5) (b / a) sum_{n = 1, 3, 5, ...} tanh(n pi a / (2b)) / n^5],
/// summed to n = 101 (truncation < 1e-9 relative). J = 0.1406 a^4 for a square.
/// The material is given by E and the shear modulus G (not Poisson's ratio: G = E / (2 (1 + nu))
/// for an isotropic material, TimoshenkoGoodier1970; G directly covers orthotropic rods too), as circularSection3d.
/// The shear factors are Cowper's for the rectangle (rectangleShearFactor; Cowper1966).
/// No checks here: BeamSection3d::validate (called by the element) rejects bad values.
BeamSection3d rectangularSection3d(double widthY, double heightZ, double youngsModulus, double shearModulus,
                                   double density, double damping = 0.0);

/// Solid circular section of diameter d: A = pi d^2 / 4, Iy = Iz = pi d^4 / 64 and
/// J = Ip = pi d^4 / 32 (a circle does not warp: TimoshenkoGoodier1970); Cowper's shear
/// factors (circleShearFactor; Cowper1966).
BeamSection3d circularSection3d(double diameter, double youngsModulus, double shearModulus, double density,
                                double damping = 0.0);

}  // namespace flexmbd
