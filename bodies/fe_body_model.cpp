// Derivation (docs/fe-import.md; definitions of Doc003 / Shabana2005, ch. 5, as in
// docs/spatial-flexible.md). A solid element mesh moves
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
// D_ff = diag(2 zeta omega_i) with the mass-normalised modes (GeradinRixen, 2.3).
// The cross terms (k != l) are not blocks of M (which is zero there): they need m_ab,
// so the mass must have the solid element structure, checked below. Solid nodes carry
// no rotation: rotation shapes zero, rKL and hI absent.
//
// Nodes with rotations (beams, shells: 6 DOF per node; docs/fe-import.md "Beams and
// shells"): the shape functions are the element's own and M has no such structure. What
// the rigid motions R (translations r_k, rotations rho_k) give holds for any M whose
// shape functions reproduce them: m and the first moment from R^T M R, the inertia tensor
// I_kl = rho_k^T M rho_l (second moment tr(I)/2 1 - I), S-bar row k = r_k^T M, and
// positionShape[k] row l = g_kl^T M with g_kl the nodal interpolant of the field u0_k e_l
// (exact for the rotations' antisymmetric parts; exact for fields the elements reproduce).
// The S_kl are lumped: node a a rigid particle of mass m_a (HRZ: M's translational
// diagonal scaled to m) with the inertia J_a of M's rotational node block. m_ff = M.
#include "bodies/fe_body_model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "bodies/modal_reduction.hpp"
#include "core/rotation_3d.hpp"
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

/// The set's centroid, relative positions and H = sum (|r|^2 1 - r r^T) (Mat3 inverse).
struct NodeSetGeometry {
  Vec3 centroid = Vec3::Zero();
  std::vector<Vec3> r;
  Mat3 Hinv = Mat3::Zero();
};

/// @throws InputError naming `owner` and the interface: fewer than 3 nodes, a node out of
/// range or twice, the nodes on one line. A rigid interface over nodes that all have
/// rotations (beams, shells) needs one node at least: the nodes' own rotations fix the frame's.
NodeSetGeometry nodeSetGeometry(const FeBodyData& d, const FeInterface& f, const std::string& owner) {
  const std::string who = owner + ": interface '" + f.name + "'";
  const std::vector<int> rot = d.rotationIndex();
  bool rotating = f.kind == FeInterfaceKind::Rigid && !f.nodes.empty();
  for (int a : f.nodes) rotating = rotating && a >= 0 && a < d.numNodes() && rot[3 * a] >= 0;
  if (f.nodes.empty() || (f.nodes.size() < 3 && !rotating)) {
    throw InputError(who + " has " + std::to_string(f.nodes.size()) +
                     " nodes; expected at least 3 not on one line (or, for a rigid interface, one node with "
                     "rotations at least)");
  }
  std::vector<char> seen(d.numNodes(), 0);
  NodeSetGeometry g;
  for (int a : f.nodes) {
    if (a < 0 || a >= d.numNodes()) throw InputError(who + ": node index " + std::to_string(a) + " is not in the mesh");
    if (seen[a]++) throw InputError(who + ": node " + std::to_string(d.nodeIds[a]) + " is given twice");
    g.centroid += d.coordinates[a];
  }
  if (rotating) {  // the frame's rotation is the nodes' own: no least-squares rotation needed
    g.centroid /= static_cast<double>(f.nodes.size());
    for (int a : f.nodes) g.r.push_back(d.coordinates[a] - g.centroid);
    return g;
  }
  g.centroid /= static_cast<double>(f.nodes.size());
  Mat3 H = Mat3::Zero();
  double size = 0.0;
  for (int a : f.nodes) {
    g.r.push_back(d.coordinates[a] - g.centroid);
    const Vec3& r = g.r.back();
    H += r.squaredNorm() * Mat3::Identity() - r * r.transpose();  // int r~^T r~
    size = std::max(size, r.squaredNorm());
  }
  // collinear nodes: H has a zero eigenvalue (rotation about the line); 1e-10 of the largest
  // |r|^2 n is round-off of the coordinates, not a thin set
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(H);
  if (!(eig.eigenvalues()[0] > 1e-10 * size * static_cast<double>(f.nodes.size()))) {
    throw InputError(who + ": its nodes lie on one line; the rotation about it is undefined (expected at least 3 "
                     "nodes not on one line)");
  }
  g.Hinv = H.inverse();
  return g;
}

/// The rigid interfaces' map q_nodal = T q (q: the DOF not in a rigid set, in matrix order,
/// then 6 per rigid interface, u_I then theta_I): u_a = u_I + theta_I x r_a, r_a = X_a - X_I.
/// `masters[k]`: interface k's first column (-1 for averaging ones).
SpMat rigidInterfaceMap(const FeBodyData& d, const FeBodyOptions& o, const std::vector<NodeSetGeometry>& geo,
                        std::vector<int>& masters, const std::string& owner) {
  const int nd = d.numDofs();
  const std::vector<int> dof = d.dofIndex(), rot = d.rotationIndex();
  std::vector<int> slaveOf(d.numNodes(), -1);
  for (std::size_t k = 0; k < o.interfaces.size(); ++k) {
    if (o.interfaces[k].kind != FeInterfaceKind::Rigid) continue;
    for (int a : o.interfaces[k].nodes) {
      if (slaveOf[a] >= 0) {
        throw InputError(owner + ": node " + std::to_string(d.nodeIds[a]) + " is in the rigid interfaces '" +
                         o.interfaces[slaveOf[a]].name + "' and '" + o.interfaces[k].name +
                         "'; a node can follow one rigid interface only");
      }
      slaveOf[a] = static_cast<int>(k);
    }
  }
  std::vector<Eigen::Triplet<double>> t;
  int col = 0;
  for (int i = 0; i < nd; ++i) {
    if (slaveOf[d.dofs[i].node] < 0) t.emplace_back(i, col++, 1.0);
  }
  masters.assign(o.interfaces.size(), -1);
  for (std::size_t k = 0; k < o.interfaces.size(); ++k) {
    const FeInterface& f = o.interfaces[k];
    if (f.kind != FeInterfaceKind::Rigid) continue;
    masters[k] = col;
    const Vec3 XI = f.atCentroid ? geo[k].centroid : f.point;
    for (int a : f.nodes) {
      const Vec3 r = d.coordinates[a] - XI;
      for (int c = 0; c < 3; ++c) {
        const int row = dof[3 * a + c];
        t.emplace_back(row, col + c, 1.0);  // u_I
        for (int j = 0; j < 3; ++j) {
          const double v = Vec3::Unit(j).cross(r)[c];  // theta_j e_j x r_a
          if (v != 0.0) t.emplace_back(row, col + 3 + j, v);
        }
        if (rot[3 * a + c] >= 0) t.emplace_back(rot[3 * a + c], col + 3 + c, 1.0);  // theta_a = theta_I
      }
    }
    col += 6;
  }
  SpMat T(nd, col);
  T.setFromTriplets(t.begin(), t.end());
  return T;
}

}  // namespace

MatX FeBodyModel::rigidBodyModes(const FeBodyData& d) {
  MatX R = MatX::Zero(d.numDofs(), 6);
  for (int i = 0; i < d.numDofs(); ++i) {
    const FeDof& f = d.dofs[i];
    if (f.isRotation()) {
      R(i, f.direction) = 1.0;  // a rotation about axis k turns every node by e_k
      continue;
    }
    R(i, f.direction) = 1.0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 r = Vec3::Unit(k).cross(d.coordinates[f.node]);  // rotation about axis k
      R(i, 3 + k) = r[f.direction];
    }
  }
  return R;
}

void FeBodyModel::addInterfaces(const FeBodyData& d, const FeBodyOptions& o, MatX& R) {
  std::vector<NodeSetGeometry> geo;
  for (const FeInterface& f : o.interfaces) geo.push_back(nodeSetGeometry(d, f, owner_));
  std::vector<int>& masters = masterColumn_;
  map_ = rigidInterfaceMap(d, o, geo, masters, owner_);
  firstInterface_ = d.numNodes();
  if (map_.cols() != map_.rows()) {
    // condensed: every invariant (points included) through T; the rigid motions too, the
    // frames' rows from their own u_I = t + theta x X_I, theta_I = theta
    nodal_ = nodal_.transformed(map_);
    MatX Rc = MatX::Zero(map_.cols(), 6);
    int firstMaster = static_cast<int>(map_.cols());
    for (int c : masters) {
      if (c >= 0) firstMaster = std::min(firstMaster, c);
    }
    for (int j = 0; j < firstMaster; ++j) {  // a DOF kept as it is: its own rows of R
      Rc.row(j) = R.row(SpMat::InnerIterator(map_, j).row());
    }
    for (std::size_t k = 0; k < masters.size(); ++k) {
      if (masters[k] < 0) continue;
      const Vec3 XI = o.interfaces[k].atCentroid ? geo[k].centroid : o.interfaces[k].point;
      for (int j = 0; j < 3; ++j) {
        Rc.block<3, 1>(masters[k], j) = Vec3::Unit(j);                      // translation: u_I = e_j
        Rc.block<3, 1>(masters[k], 3 + j) = Vec3::Unit(j).cross(XI);        // rotation: u_I = e_j x X_I
        Rc(masters[k] + 3 + j, 3 + j) = 1.0;                                // theta_I = e_j
      }
    }
    R = Rc;
  }
  for (std::size_t k = 0; k < o.interfaces.size(); ++k) {
    const FeInterface& f = o.interfaces[k];
    const Vec3 XI = f.atCentroid ? geo[k].centroid : f.point;
    FfrPoint3d p;
    p.position = XI;
    const int n = static_cast<int>(nodal_.mff.rows());
    p.shape = Mat3X::Zero(3, n);
    p.rotationShape = Mat3X::Zero(3, n);
    if (f.kind == FeInterfaceKind::Rigid) {
      for (int c = 0; c < 3; ++c) {
        p.shape(c, masters[k] + c) = 1.0;
        p.rotationShape(c, masters[k] + 3 + c) = 1.0;
      }
    } else {
      // RBE3: u_c = mean N_a, theta = H^-1 sum r_a x (N_a q), u_I = u_c + theta x (X_I - X_c)
      for (std::size_t i = 0; i < f.nodes.size(); ++i) {
        const Mat3X& Na = nodal_.points[f.nodes[i]].shape;
        p.shape += Na / static_cast<double>(f.nodes.size());
        p.rotationShape += geo[k].Hinv * (skew(geo[k].r[i]) * Na);
      }
      p.shape -= skew(XI - geo[k].centroid) * p.rotationShape;  // theta x d = -d~ theta
    }
    nodal_.points.push_back(std::move(p));
  }
}

namespace {

/// The nodal invariants of a solid mesh (no rotations), exact for the mesh's mass matrix
/// `mass` (point masses included) and node mass `m` (derivation at the top of this file).
FfrInvariants3d solidInvariants(const FeBodyData& d, const SpMat& m, const SpMat& mass) {
  const int nn = d.numNodes(), nd = d.numDofs();
  const std::vector<int> dof = d.dofIndex();
  MatX X(nn, 3);
  for (int a = 0; a < nn; ++a) X.row(a) = d.coordinates[a].transpose();
  const VecX m1 = m * VecX::Ones(nn);  // sum_a m_ab (m symmetric)
  const MatX mX = m * X;               // sum_b m_ab X_bk
  FfrInvariants3d v;
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
  return v;
}

/// The nodal invariants of a mesh whose nodes have rotations (beams, shells; derivation at
/// the top of this file and docs/fe-import.md "Beams and shells"): exact for the rigid
/// motions, lumped at the nodes for the rest. `R`: rigidBodyModes(d).
FfrInvariants3d structuralInvariants(const FeBodyData& d, const SpMat& mass, const MatX& R) {
  const int nn = d.numNodes(), nd = d.numDofs();
  const std::vector<int> dof = d.dofIndex(), rot = d.rotationIndex();
  const MatX MR = mass * R;
  const Eigen::Matrix<double, 6, 6> A = R.transpose() * MR;  // the rigid body's mass matrix about the origin
  FfrInvariants3d v;
  // m = r_k^T M r_k; t_k^T M rho_l = (e_l x first)_k; rho_k^T M rho_l = I_kl (Shabana2005, 5.2)
  v.mass = A.topLeftCorner<3, 3>().trace() / 3.0;
  v.firstMoment = 0.5 * Vec3(A(1, 5) - A(2, 4), A(2, 3) - A(0, 5), A(0, 4) - A(1, 3));
  const Mat3 I = 0.5 * (A.bottomRightCorner<3, 3>() + A.bottomRightCorner<3, 3>().transpose());
  // int rho u0 u0^T = tr(I)/2 1 - I (inverting I = tr(J) 1 - J, Shabana2005, eq. 5.110)
  v.secondMoment = 0.5 * I.trace() * Mat3::Identity() - I;
  v.sBar = MR.leftCols<3>().transpose();                     // row k = r_k^T M
  // positionShape[k] row l = g_kl^T M, g_kl the nodal interpolant of the field u0_k e_l:
  // translations X_ak e_l, rotations its curl / 2 = (e_k x e_l) / 2 (exact for rigid rotations)
  for (int k = 0; k < 3; ++k) {
    v.positionShape[k] = Mat3X::Zero(3, nd);
    for (int l = 0; l < 3; ++l) {
      VecX g = VecX::Zero(nd);
      const Vec3 curl = 0.5 * Vec3::Unit(k).cross(Vec3::Unit(l));
      for (int a = 0; a < nn; ++a) {
        g[dof[3 * a + l]] = d.coordinates[a][k];
        for (int c = 0; c < 3; ++c) {
          if (rot[3 * a + c] >= 0) g[rot[3 * a + c]] = curl[c];
        }
      }
      v.positionShape[k].row(l) = (mass * g).transpose();
    }
  }
  // S_kl lumped: node a a rigid particle of mass m_a (HRZ: M's translational diagonal scaled
  // to the total mass) with the rotational inertia J_a of M's node block, C_a = tr(J_a)/2 1 - J_a:
  // S_kl(t_ak, t_al) = m_a, S_kl(theta_am, theta_an) = eps_kmj eps_lni C_a(j, i)
  VecX diag = VecX::Zero(nn);
  double trace = 0.0;
  for (int a = 0; a < nn; ++a) {
    for (int k = 0; k < 3; ++k) diag[a] += mass.coeff(dof[3 * a + k], dof[3 * a + k]);
    trace += diag[a];
  }
  const VecX ma = diag * (v.mass / trace);
  const auto eps = [](int i, int j, int k) { return 0.5 * (i - j) * (j - k) * (k - i); };  // Levi-Civita, 0..2
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      Triplets t;
      for (int a = 0; a < nn; ++a) {
        t.emplace_back(dof[3 * a + k], dof[3 * a + l], ma[a]);
        if (rot[3 * a] < 0) continue;
        Mat3 J;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) J(i, j) = mass.coeff(rot[3 * a + i], rot[3 * a + j]);
        const Mat3 C = 0.5 * J.trace() * Mat3::Identity() - 0.5 * (J + J.transpose());
        for (int mm = 0; mm < 3; ++mm) {
          for (int n = 0; n < 3; ++n) {
            double s = 0.0;
            for (int j = 0; j < 3; ++j)
              for (int i = 0; i < 3; ++i) s += eps(k, mm, j) * eps(l, n, i) * C(j, i);
            if (s != 0.0) t.emplace_back(rot[3 * a + mm], rot[3 * a + n], s);
          }
        }
      }
      v.sKL[k][l].resize(nd, nd);
      v.sKL[k][l].setFromTriplets(t.begin(), t.end());
    }
  }
  v.mff = mass;
  return v;
}

}  // namespace

FeBodyModel::FeBodyModel(const FeBodyData& d, const FeBodyOptions& options, std::string owner)
    : owner_(std::move(owner)) {
  if (!(options.stiffnessScale > 0.0) || !std::isfinite(options.stiffnessScale)) {
    throw InputError(owner_ + ": stiffness scale " + fmt(options.stiffnessScale) + "; expected a positive number");
  }
  if (!(options.dampingRatio >= 0.0 && options.dampingRatio <= 1.0)) {
    throw InputError(owner_ + ": damping ratio " + fmt(options.dampingRatio) + "; expected a number in [0, 1]");
  }
  const int nn = d.numNodes(), nd = d.numDofs();
  const std::vector<int> dof = d.dofIndex(), rot = d.rotationIndex();
  const bool structural = d.hasRotations();
  SpMat m = structural ? SpMat() : nodeMass(d, owner_);
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
    if (!structural) m.coeffRef(p.node, p.node) += p.mass;  // lumped: m_aa += m_p
    for (int k = 0; k < 3; ++k) mass.coeffRef(dof[3 * p.node + k], dof[3 * p.node + k]) += p.mass;
  }

  // the rigid motions of the nodes must be the stiffness's null space: coordinates and DOF
  // map are those of the matrices (measured 6e-16 and 3e-13 for the rotor's two exports)
  constexpr double kRigidTolerance = 1e-8;
  MatX R = rigidBodyModes(d);
  const double kr = (d.stiffness * R).cwiseAbs().maxCoeff() / (maxAbsOf(d.stiffness) * R.cwiseAbs().maxCoeff());
  if (kr > kRigidTolerance) {
    throw InputError(owner_ + ": the stiffness of " + d.source +
                     " does not vanish on the rigid motions of the nodes (" + fmt(kr, 3) +
                     " of |K| |r|, expected <= 1e-8): the coordinates or the DOF map are not those of "
                     "the matrices, or the export holds supports");
  }

  nodal_ = structural ? structuralInvariants(d, mass, R) : solidInvariants(d, m, mass);
  nodal_.kff = options.stiffnessScale * d.stiffness;
  nodal_.dff.resize(nd, nd);
  for (int a = 0; a < nn; ++a) {  // every node an attachment point, with its rotation if it has one
    FfrPoint3d p;
    p.position = d.coordinates[a];
    p.shape = Mat3X::Zero(3, nd);
    p.rotationShape = Mat3X::Zero(3, nd);
    for (int k = 0; k < 3; ++k) {
      p.shape(k, dof[3 * a + k]) = 1.0;
      if (rot[3 * a + k] >= 0) p.rotationShape(k, rot[3 * a + k]) = 1.0;
    }
    nodal_.points.push_back(std::move(p));
  }

  if (options.spinStiffening.preloadedStiffness.size()) addSpinStiffening(d, options);
  addInterfaces(d, options, R);
  if (options.reduction == FeReduction::CraigBampton) {
    reduceCraigBampton(options);
  } else {
    basis_ = freeFreeModes(nodal_.kff, nodal_.mff, R, options.modes, owner_, &omega_, &rigidEigenvalues_);
  }
  if (options.inertiaModes) addInertiaModes(options, R);
  reduced_ = nodal_.transformed(basis_.sparseView());
  if (options.dampingRatio > 0.0) addModalDamping(options.dampingRatio);
}

void FeBodyModel::addSpinStiffening(const FeBodyData& d, const FeBodyOptions& o) {
  const FeSpinStiffening& st = o.spinStiffening;
  const int nd = d.numDofs();
  const double w2 = st.spin.squaredNorm();
  if (!(w2 > 0.0) || !std::isfinite(w2)) {
    throw InputError(owner_ + ": spin stiffening: the preload spin is " + fmt(std::sqrt(w2)) +
                     " rad/s; expected the spin of the preloaded export, not zero");
  }
  if (st.preloadedStiffness.rows() != nd || st.preloadedStiffness.cols() != nd) {
    throw InputError(owner_ + ": spin stiffening: the preloaded stiffness is " +
                     std::to_string(st.preloadedStiffness.rows()) + " x " + std::to_string(st.preloadedStiffness.cols()) +
                     "; expected the body's " + std::to_string(nd) + " DOF");
  }
  // the DOF the preload run held must be held by the body too: its Craig-Bampton reference
  std::vector<char> reference(d.numNodes(), 0);
  bool haveReference = false;
  for (const FeInterface& f : o.interfaces) {
    if (o.reduction == FeReduction::CraigBampton && f.name == o.reference && f.kind == FeInterfaceKind::Rigid) {
      haveReference = true;
      for (int a : f.nodes) reference[a] = 1;
    }
  }
  if (!haveReference) {
    throw InputError(owner_ + ": spin stiffening needs \"reduction\": \"craig_bampton\" with a rigid reference "
                     "interface over the nodes the preload run held (a spinning body is held at its hub)");
  }
  std::vector<char> held(nd, 0);
  for (int i : st.heldDofs) {
    held[i] = 1;
    if (!reference[d.dofs[i].node]) {
      throw InputError(owner_ + ": spin stiffening: the preload run held node " + std::to_string(d.nodeIds[d.dofs[i].node]) +
                       ", which the reference interface '" + o.reference + "' does not hold");
    }
  }
  // K_sigma = K_pre - K + |w|^2 M_perp on the DOF the export has (the held ones: zero)
  const Vec3 e = st.spin / std::sqrt(w2);
  SpMat Mperp(nd, nd);
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) Mperp += ((k == l ? 1.0 : 0.0) - e[k] * e[l]) * nodal_.sKL[k][l];
  SpMat Ksigma = st.preloadedStiffness - d.stiffness + w2 * Mperp;
  Ksigma.prune([&](Eigen::Index r, Eigen::Index c, double) { return !held[r] && !held[c]; });
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      if (e[k] * e[l] != 0.0) nodal_.spinStiffness[k][l] = (e[k] * e[l] / w2) * Ksigma;
    }
  }
}

void FeBodyModel::addInertiaModes(const FeBodyOptions& options, const MatX& R) {
  const MatX F = nodal_.inertiaLoads();
  const SpMat& K = nodal_.kff;
  if (options.reduction == FeReduction::FreeFree) {
    basis_ = withStaticResponses(K, nodal_.mff, basis_, freeStaticResponses(K, nodal_.mff, R, F, owner_));
    return;
  }
  // Craig-Bampton (CraigBampton1968): K y = F on the DOF other than the reference interface's (held: y = 0)
  const int n = static_cast<int>(K.rows());
  std::vector<int> free(n, 0);
  for (int i : held_) free[i] = -1;
  int nFree = 0;
  for (int i = 0; i < n; ++i) free[i] = free[i] < 0 ? -1 : nFree++;
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < K.outerSize(); ++j) {
    for (SpMat::InnerIterator it(K, j); it; ++it) {
      if (free[it.row()] >= 0 && free[j] >= 0) t.emplace_back(free[it.row()], free[j], it.value());
    }
  }
  SpMat Kf(nFree, nFree);
  Kf.setFromTriplets(t.begin(), t.end());
  MatX Ff(nFree, F.cols());
  for (int i = 0; i < n; ++i) {
    if (free[i] >= 0) Ff.row(free[i]) = F.row(i);
  }
  const Eigen::SimplicialLDLT<SpMat> ldlt(Kf);
  const MatX Yf = ldlt.solve(Ff);
  MatX Y = MatX::Zero(n, F.cols());
  for (int i = 0; i < n; ++i) {
    if (free[i] >= 0) Y.row(i) = Yf.row(free[i]);
  }
  basis_ = withStaticResponses(K, nodal_.mff, basis_, Y);
}

void FeBodyModel::addModalDamping(double zeta) {
  // D_ff = diag(2 zeta omega) on the (free-free or fixed-interface) normal modes; none on
  // constraint or inertia modes (GeradinRixen, 2.3)
  const int nm = static_cast<int>(omega_.size());
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < nm; ++i) t.emplace_back(firstNormal_ + i, firstNormal_ + i, 2.0 * zeta * omega_[i]);
  reduced_.dff.resize(basis_.cols(), basis_.cols());
  reduced_.dff.setFromTriplets(t.begin(), t.end());
}

void FeBodyModel::reduceCraigBampton(const FeBodyOptions& o) {
  int ref = -1;
  std::string names;
  for (std::size_t k = 0; k < o.interfaces.size(); ++k) {
    if (o.interfaces[k].name == o.reference) ref = static_cast<int>(k);
    if (o.interfaces[k].kind == FeInterfaceKind::Rigid) names += (names.empty() ? "'" : ", '") + o.interfaces[k].name + "'";
  }
  if (ref < 0 || masterColumn_[ref] < 0) {
    throw InputError(owner_ + ": Craig-Bampton needs the reference to be a rigid interface the frame follows; '" +
                     o.reference + "' is " + (ref < 0 ? "not an interface" : "an averaging interface") +
                     " (rigid interfaces: " + (names.empty() ? std::string("none") : names) + ")");
  }
  const int n = static_cast<int>(nodal_.kff.rows());
  std::vector<int> held, boundary;
  for (int c = 0; c < 6; ++c) held.push_back(masterColumn_[ref] + c);
  for (std::size_t k = 0; k < masterColumn_.size(); ++k) {
    if (static_cast<int>(k) == ref || masterColumn_[k] < 0) continue;
    for (int c = 0; c < 6; ++c) boundary.push_back(masterColumn_[k] + c);
  }
  // fixed-interface modes: every rigid interface held
  std::vector<int> fixed = held;
  fixed.insert(fixed.end(), boundary.begin(), boundary.end());
  const MatX Phi = clampedModes(nodal_.kff, nodal_.mff, fixed, o.modes, owner_, &omega_);
  // constraint modes (CraigBampton1968): psi_b = e_b at the boundary, 0 at the reference,
  // -K_ii^-1 K_ib inside
  std::vector<int> inner(n, 0);  // position among the inner DOF, or -1
  for (int i : fixed) inner[i] = -1;
  int ni = 0;
  for (int i = 0; i < n; ++i) inner[i] = inner[i] < 0 ? -1 : ni++;
  std::vector<int> bpos(n, -1);
  for (std::size_t j = 0; j < boundary.size(); ++j) bpos[boundary[j]] = static_cast<int>(j);
  std::vector<Eigen::Triplet<double>> tii, tib;
  for (int j = 0; j < nodal_.kff.outerSize(); ++j) {
    for (SpMat::InnerIterator it(nodal_.kff, j); it; ++it) {
      const int r = inner[it.row()];
      if (r < 0) continue;
      if (inner[j] >= 0) tii.emplace_back(r, inner[j], it.value());
      if (bpos[j] >= 0) tib.emplace_back(r, bpos[j], it.value());
    }
  }
  SpMat Kii(ni, ni), Kib(ni, static_cast<int>(boundary.size()));
  Kii.setFromTriplets(tii.begin(), tii.end());
  Kib.setFromTriplets(tib.begin(), tib.end());
  const Eigen::SimplicialLDLT<SpMat> ldlt(Kii);
  if (ldlt.info() != Eigen::Success) {
    throw InputError(owner_ + ": the stiffness with the rigid interfaces held is singular (a part of the body moves "
                     "freely: is every part connected to an interface?)");
  }
  const MatX inside = -(ldlt.solve(MatX(Kib)));  // -K_ii^-1 K_ib (CraigBampton1968)
  MatX Psi = MatX::Zero(n, static_cast<int>(boundary.size()));
  for (std::size_t j = 0; j < boundary.size(); ++j) Psi(boundary[j], static_cast<int>(j)) = 1.0;
  for (int i = 0; i < n; ++i) {
    if (inner[i] >= 0) Psi.row(i) = inside.row(inner[i]);
  }
  basis_.resize(n, Psi.cols() + Phi.cols());
  basis_ << Psi, Phi;
  held_ = held;
  firstNormal_ = static_cast<int>(Psi.cols());
}

}  // namespace flexmbd
