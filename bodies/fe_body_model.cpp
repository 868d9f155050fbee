// Derivation (docs/fe-import.md; definitions of document 003 / Shabana, Dynamics of
// Multibody Systems, ch. 5, as in docs/spatial-flexible.md). A solid element mesh moves
// its material points by u(P) = sum_a n_a(P) (X_a + q_a): the same shape functions
// carry the geometry X_a and the nodal displacements q_a (isoparametric elements; a
// lumped mass is the case of point masses at the nodes). Its mass matrix is then
// M(a k, b l) = delta_kl m_ab with m_ab = int rho n_a n_b dV, and with sum_a n_a = 1:
//   m          = int rho dV              = sum_ab m_ab                 (= r_k^T M r_k)
//   first_k    = int rho u0_k dV         = sum_ab X_ak m_ab            (= r_k^T M x_k)
//   J_kl       = int rho u0_k u0_l dV    = sum_ab X_ak m_ab X_bl       (J_kk = x_k^T M x_k)
//   S-bar(k, (b k))        = int rho n_b dV        = sum_a m_ab        (row k = r_k^T M)
//   positionShape[k](l, (b l)) = int rho u0_k n_b dV = sum_a X_ak m_ab
//   S_kl((a k), (b l))     = int rho n_a n_b dV    = m_ab              (S_kk = D_k M D_k)
//   m_ff = S_xx + S_yy + S_zz = M,  K_ff = K (scaled).
// A point mass m_p at node a is a lumped m_aa += m_p (M gains it in the node's three
// diagonal entries), so every invariant above includes it; modal damping
// D_ff = diag(2 zeta omega_i) with the mass-normalised modes (Geradin & Rixen, 2.3).
// The cross terms (k != l) are not blocks of M (which is zero there): they need m_ab,
// so the mass must have the solid element structure, checked below. Solid nodes carry
// no rotation: rotation shapes zero, rKL and hI absent.
#include "bodies/fe_body_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "bodies/modal_reduction.hpp"
#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

double maxAbsOf(const SpMat& A) {
  double m = 0.0;
  for (int j = 0; j < A.outerSize(); ++j) {
    for (SpMat::InnerIterator it(A, j); it; ++it) m = std::max(m, std::abs(it.value()));
  }
  return m;
}

/// The node mass matrix m_ab (N x N) of M = m (x) I_3 in the DOF order of `d`.
/// @throws InputError naming `owner` if M couples directions or differs between them.
SpMat nodeMass(const FeBodyData& d, const std::string& owner) {
  constexpr double kStructureTolerance = 1e-10;  // of max |M|: round-off of the printed entries is 1e-16
  const int nn = d.numNodes(), nd = d.numDofs();
  Triplets t;
  for (int j = 0; j < d.mass.outerSize(); ++j) {
    for (SpMat::InnerIterator it(d.mass, j); it; ++it) {
      const FeDof &a = d.dofs[it.row()], &b = d.dofs[j];
      if (a.direction == 0 && b.direction == 0) t.emplace_back(a.node, b.node, it.value());
    }
  }
  SpMat m(nn, nn);
  m.setFromTriplets(t.begin(), t.end());
  const std::vector<int> dof = d.dofIndex();
  Triplets full;
  for (int j = 0; j < m.outerSize(); ++j) {
    for (SpMat::InnerIterator it(m, j); it; ++it) {
      for (int k = 0; k < 3; ++k) full.emplace_back(dof[3 * it.row() + k], dof[3 * j + k], it.value());
    }
  }
  SpMat rebuilt(nd, nd);
  rebuilt.setFromTriplets(full.begin(), full.end());
  const double scale = maxAbsOf(d.mass);
  const double diff = maxAbsOf(SpMat(d.mass - rebuilt));
  if (diff > kStructureTolerance * scale) {
    throw InputError(owner + ": the mass matrix of " + d.source + " differs by " + fmt(diff, 3) + " (largest entry " +
                     fmt(scale, 3) +
                     ") from a solid element mass; expected M(a k, b l) = delta_kl m_ab (no coupling between "
                     "directions, the same in x, y, z)");
  }
  return m;
}

}  // namespace

MatX FeBodyModel::rigidBodyModes(const FeBodyData& d) {
  MatX R = MatX::Zero(d.numDofs(), 6);
  for (int i = 0; i < d.numDofs(); ++i) {
    const FeDof& f = d.dofs[i];
    R(i, f.direction) = 1.0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 r = Vec3::Unit(k).cross(d.coordinates[f.node]);  // rotation about axis k
      R(i, 3 + k) = r[f.direction];
    }
  }
  return R;
}

FeBodyModel::FeBodyModel(const FeBodyData& d, const FeBodyOptions& options, std::string owner)
    : owner_(std::move(owner)) {
  if (!(options.stiffnessScale > 0.0) || !std::isfinite(options.stiffnessScale)) {
    throw InputError(owner_ + ": stiffness scale " + fmt(options.stiffnessScale) + "; expected a positive number");
  }
  if (!(options.dampingRatio >= 0.0 && options.dampingRatio <= 1.0)) {
    throw InputError(owner_ + ": damping ratio " + fmt(options.dampingRatio) + "; expected a number in [0, 1]");
  }
  const int nn = d.numNodes(), nd = d.numDofs();
  const std::vector<int> dof = d.dofIndex();
  SpMat m = nodeMass(d, owner_);
  SpMat mass = d.mass;
  for (const FePointMass& p : options.pointMasses) {
    if (p.node < 0 || p.node >= nn) {
      throw InputError(owner_ + ": a point mass at node index " + std::to_string(p.node) + "; the mesh has " +
                       std::to_string(nn) + " nodes");
    }
    if (!(p.mass > 0.0) || !std::isfinite(p.mass)) {
      throw InputError(owner_ + ": point mass " + fmt(p.mass) + " at node " + std::to_string(d.nodeIds[p.node]) +
                       "; expected a positive mass");
    }
    m.coeffRef(p.node, p.node) += p.mass;  // lumped: m_aa += m_p
    for (int k = 0; k < 3; ++k) mass.coeffRef(dof[3 * p.node + k], dof[3 * p.node + k]) += p.mass;
  }
  MatX X(nn, 3);
  for (int a = 0; a < nn; ++a) X.row(a) = d.coordinates[a].transpose();
  const VecX m1 = m * VecX::Ones(nn);  // sum_a m_ab (m symmetric)
  const MatX mX = m * X;               // sum_b m_ab X_bk

  // the rigid motions of the nodes must be the stiffness's null space: coordinates and DOF
  // map are those of the matrices (measured 6e-16 and 3e-13 for the rotor's two exports)
  constexpr double kRigidTolerance = 1e-8;
  const MatX R = rigidBodyModes(d);
  const double kr = (d.stiffness * R).cwiseAbs().maxCoeff() / (maxAbsOf(d.stiffness) * R.cwiseAbs().maxCoeff());
  if (kr > kRigidTolerance) {
    throw InputError(owner_ + ": the stiffness of " + d.source +
                     " does not vanish on the rigid motions of the nodes (" + fmt(kr, 3) +
                     " of |K| |r|, expected <= 1e-8): the coordinates or the DOF map are not those of "
                     "the matrices, or the export holds supports");
  }

  FfrInvariants3d& v = nodal_;
  v.mass = m1.sum();
  v.firstMoment = X.transpose() * m1;
  v.secondMoment = X.transpose() * mX;
  v.sBar = Mat3X::Zero(3, nd);
  for (int k = 0; k < 3; ++k) {
    v.positionShape[k] = Mat3X::Zero(3, nd);
    for (int b = 0; b < nn; ++b) {
      v.sBar(k, dof[3 * b + k]) = m1[b];
      for (int l = 0; l < 3; ++l) v.positionShape[k](l, dof[3 * b + l]) = mX(b, k);
    }
    for (int l = 0; l < 3; ++l) {
      Triplets t;
      for (int j = 0; j < m.outerSize(); ++j) {
        for (SpMat::InnerIterator it(m, j); it; ++it) t.emplace_back(dof[3 * it.row() + k], dof[3 * j + l], it.value());
      }
      v.sKL[k][l].resize(nd, nd);
      v.sKL[k][l].setFromTriplets(t.begin(), t.end());
    }
  }
  v.mff = mass;
  v.kff = options.stiffnessScale * d.stiffness;
  v.dff.resize(nd, nd);
  for (int a = 0; a < nn; ++a) {
    FfrPoint3d p;
    p.position = d.coordinates[a];
    p.shape = Mat3X::Zero(3, nd);
    for (int k = 0; k < 3; ++k) p.shape(k, dof[3 * a + k]) = 1.0;
    p.rotationShape = Mat3X::Zero(3, nd);
    v.points.push_back(std::move(p));
  }

  basis_ = freeFreeModes(v.kff, v.mff, R, options.modes, owner_, &omega_, &rigidEigenvalues_);
  reduced_ = nodal_.transformed(basis_.sparseView());
  if (options.dampingRatio > 0.0) {
    reduced_.dff = SpMat(VecX(2.0 * options.dampingRatio * omega_).asDiagonal());  // D_ff = diag(2 zeta omega)
  }
}

}  // namespace flexmbd
