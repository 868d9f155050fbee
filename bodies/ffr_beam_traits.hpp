/// @file
/// What a planar and a spatial beam model do differently (FfrBeamModelT,
/// bodies/ffr_beam_model.hpp): the node's coordinates (3 or 6), the element, the
/// element's inertia shape integrals summed into the body's invariants, the pinned-pinned
/// and mean-axis reference conditions, the inertia loads of the frame's rigid motion, and
/// the shape of a point on an element. PlanarBeam: bodies/ffr_beam_planar.cpp;
/// SpatialBeam: bodies/ffr_beam_spatial.cpp.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Sparse>

#include "bodies/beam_mesh.hpp"
#include "bodies/ffr_beam_options.hpp"
#include "bodies/ffr_invariants.hpp"
#include "bodies/ffr_invariants_3d.hpp"
#include "elements/beam_element_2d.hpp"
#include "elements/beam_element_3d.hpp"

namespace flexmbd {

using Triplets = std::vector<Eigen::Triplet<double>>;

/// What follows from the dimension alone: a node's coordinates (Dim translations and
/// 1 or 3 rotations), the two-node element's, points, rotations, options.
template <int Dim>
struct BeamDimension {
  static constexpr int kDim = Dim;
  static constexpr int kNodeDofs = Dim == 2 ? 3 : 6;
  static constexpr int kElementDofs = 2 * kNodeDofs;
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Rotation = Eigen::Matrix<double, Dim, Dim>;
  using Options = FfrBeamOptionsT<Dim>;
  using ElementVector = Eigen::Matrix<double, kElementDofs, 1>;
  using ElementMatrix = Eigen::Matrix<double, kElementDofs, kElementDofs>;
  /// The rows of an element's nodal coordinates in the body's (node 1, then node 2).
  using ElementRows = std::array<int, kElementDofs>;
};

/// Planar beams: ux, uy, psi per node (body frame), BeamElement2d.
struct PlanarBeam : BeamDimension<2> {
  using Mesh = BeamMesh2d;
  using Element = BeamElement2d;
  using Invariants = FfrInvariants;
  using SectionForces = Vec2;  ///< axial force, bending moment
  /// Name of a node's coordinate k: u_x, u_y, psi.
  static const char* nodeDofName(int k);
  /// How errors name reference node A or B ("node"; spatial: "node A", "node B").
  static const char* referenceNodeName(char) { return "node"; }

  /// The element `e` of the mesh. @throws InputError for Rayleigh (not yet planar).
  static Element makeElement(const Mesh& mesh, int e, const Options& options, const std::string& who);
  /// The element's mass matrix in element axes, S_xx + S_yy.
  static ElementMatrix elementMass(const Element& el) { return el.sXX() + el.sYY(); }

  /// The planar inertia shape integrals of the nodal body (mass, first and polar moment,
  /// S-bar, I1, J0, S~), summed element by element.
  class InertiaAssembly {
   public:
    explicit InertiaAssembly(int numNodalDofs);
    /// Adds element `el` whose nodal coordinates are the rows `idx` of the body's.
    void add(const Element& el, const ElementRows& idx);
    /// The invariants summed so far (m_ff, K_ff, D_ff to be set by the caller).
    Invariants finish();

   private:
    int nd_;
    Invariants nodal_;
    Triplets tSTilde_;
    Triplets tR_;  // R (Rayleigh and Timoshenko elements only)
  };

  /// Conditions C q_n = 0 of the chord frame: node a fixed, node b on the chord a-b (Doc003's
  /// pinned-pinned reference conditions).
  static void pinnedPinnedRows(int a, int b, const Mesh& mesh, MatX& C, std::vector<std::string>& names,
                               const std::string& owner);
  /// The mean-axis rotation condition int rho u0 x u_f dV = J0^T q_n = 0 (Shabana2005, ch. 5):
  /// row 2 of C.
  static void meanAxisRotationRows(const Invariants& nodal, MatX& C, std::vector<std::string>& names);
  /// Inertia loads of the frame's rigid motion on q_f at q_f = 0 (Q_v, Q_g in
  /// docs/flexible-bodies.md): translation S-bar^T, centrifugal I1, angular J0.
  static MatX inertiaLoads(const Invariants& reduced);

  /// The element axes in the body frame (columns), R(beta).
  static Rotation axisRotation(const Element& el) { return rotation(el.angle()); }
  /// Distance of a point (element axes) from the element axis.
  static double distanceFromAxis(const Point& local) { return std::abs(local.y()); }
  /// Body-frame displacement shape R S(xi) (2 x 6, element nodal coordinates).
  static Eigen::Matrix<double, 2, kElementDofs> bodyShape(const Element& el, double xi);
  /// Section rotation shape psi = S'(xi) (1 x 6, element nodal coordinates).
  static Eigen::Matrix<double, 1, kElementDofs> rotationShape(const Element& el, double xi);
};

/// Spatial beams: ux, uy, uz, thx, thy, thz per node (body frame), BeamElement3d.
struct SpatialBeam : BeamDimension<3> {
  using Mesh = BeamMesh3d;
  using Element = BeamElement3d;
  using Invariants = FfrInvariants3d;
  using SectionForces = BeamSectionForces3d;
  /// Name of a node's coordinate k: u_x, u_y, u_z, theta_x, theta_y, theta_z.
  static const char* nodeDofName(int k);
  static const char* referenceNodeName(char which) { return which == 'A' ? "node A" : "node B"; }

  static Element makeElement(const Mesh& mesh, int e, const Options& options, const std::string& who);
  /// The element's consistent mass matrix in element axes.
  static ElementMatrix elementMass(const Element& el) { return el.massMatrix(); }

  /// The spatial inertia shape integrals of the nodal body (mass, first and second
  /// moment, S-bar, position shapes, S_kl, R_kl, H_i), summed element by element.
  class InertiaAssembly {
   public:
    explicit InertiaAssembly(int numNodalDofs);
    void add(const Element& el, const ElementRows& idx);
    Invariants finish();

   private:
    int nd_;
    Invariants nodal_;
    std::array<Triplets, 9> tS_;  // S_kl at 3 k + l
    std::array<Triplets, 9> tR_;  // R_kl at 3 k + l
    std::array<Triplets, 3> tH_;  // H_i
  };

  /// Conditions of the chord frame: node a's translations, node b's transverse
  /// translations and the twist at a zero (node b on the body x axis through a).
  static void pinnedPinnedRows(int a, int b, const Mesh& mesh, MatX& C, std::vector<std::string>& names,
                               const std::string& owner);
  /// The mean-axis rotation conditions int rho u0 x u_f dV = 0 (Shabana2005, ch. 5): rows 3..5
  /// of C.
  static void meanAxisRotationRows(const Invariants& nodal, MatX& C, std::vector<std::string>& names);
  /// Inertia loads of the frame's rigid motion on q_f at q_f = 0: translation S-bar^T,
  /// and int rho N^T (W u0) dV for every 3 x 3 W (alpha~ + omega~ omega~ spans them).
  static MatX inertiaLoads(const Invariants& reduced);

  static const Rotation& axisRotation(const Element& el) { return el.rotation(); }
  static double distanceFromAxis(const Point& local) { return std::hypot(local.y(), local.z()); }
  /// Body-frame displacement shape C S(xi) (3 x 12).
  static Eigen::Matrix<double, 3, kElementDofs> bodyShape(const Element& el, double xi);
  /// Body-axis section rotation shape C (twist, -dw_z/dx, dw_y/dx) (3 x 12).
  static Eigen::Matrix<double, 3, kElementDofs> rotationShape(const Element& el, double xi);
};

static_assert(std::is_same_v<PlanarBeam::ElementVector, BeamElement2d::Vec6> &&
                  std::is_same_v<SpatialBeam::ElementMatrix, BeamElement3d::Mat12>,
              "the elements' nodal coordinates are the two nodes' (BeamDimension)");

}  // namespace flexmbd
