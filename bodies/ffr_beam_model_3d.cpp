#include "bodies/ffr_beam_model_3d.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <numeric>
#include <sstream>

#include "bodies/modal_reduction.hpp"
#include "bodies/beam_mesh_topology.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"

namespace flexmbd {
namespace {

constexpr int kNodeDofs = 6;  // ux, uy, uz, thx, thy, thz (body frame)

int dof(int node, int k) { return kNodeDofs * node + k; }

std::string nodeDofName(int row) {
  static const char* names[kNodeDofs] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};
  return std::string(names[row % kNodeDofs]) + " of node " + std::to_string(row / kNodeDofs);
}

/// Sparse null-space basis of the full-row-rank C (r x n, r small): the r coordinates
/// at the pivots of a full-pivoting LU are eliminated, q_d = -C_d^{-1} C_i q_i, and the
/// others kept (unit columns). Cost O(r^2 n) and the basis has n - r unit columns plus
/// the r eliminated rows (as nullSpaceBasis in core/linear_algebra, without its dense
/// n x (n - r) result).
SpMat sparseNullSpaceBasis(const MatX& C) {
  const int r = static_cast<int>(C.rows()), n = static_cast<int>(C.cols());
  const Eigen::FullPivLU<MatX> lu(C);
  std::vector<int> pivots(r), freeCols, freeIndex(n, -1);
  std::vector<bool> isPivot(n, false);
  for (int k = 0; k < r; ++k) {
    pivots[k] = lu.permutationQ().indices()[k];
    isPivot[pivots[k]] = true;
  }
  for (int j = 0; j < n; ++j) {
    if (!isPivot[j]) {
      freeIndex[j] = static_cast<int>(freeCols.size());
      freeCols.push_back(j);
    }
  }
  MatX Cd(r, r), Ci(r, freeCols.size());
  for (int k = 0; k < r; ++k) Cd.col(k) = C.col(pivots[k]);
  for (size_t k = 0; k < freeCols.size(); ++k) Ci.col(k) = C.col(freeCols[k]);
  const MatX X = -Cd.fullPivLu().solve(Ci);  // q_d = X q_i
  const double drop = 1e-14 * (X.size() > 0 ? X.cwiseAbs().maxCoeff() : 0.0);
  std::vector<Eigen::Triplet<double>> t;
  for (size_t k = 0; k < freeCols.size(); ++k) t.emplace_back(freeCols[k], static_cast<int>(k), 1.0);
  for (int k = 0; k < r; ++k) {
    for (int j = 0; j < X.cols(); ++j) {
      if (std::abs(X(k, j)) > drop) t.emplace_back(pivots[k], j, X(k, j));
    }
  }
  SpMat B(n, static_cast<int>(freeCols.size()));
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

}  // namespace

BeamMesh3d BeamMesh3d::straight(double length, int numElements, const BeamSection3d& section, const Vec3& origin,
                                const Vec3& yHint) {
  if (numElements < 1) throw InputError("beam mesh: elements must be >= 1, got " + std::to_string(numElements));
  requirePositive(length, "beam mesh: length");
  BeamMesh3d m;
  for (int i = 0; i <= numElements; ++i) m.nodes.push_back(origin + Vec3(length * i / numElements, 0.0, 0.0));
  for (int i = 0; i < numElements; ++i) m.elements.push_back({i, i + 1, section, yHint});
  return m;
}

FfrBeamModel3d::FfrBeamModel3d(BeamMesh3d mesh, const FfrBeamOptions3d& options, const std::string& owner)
    : mesh_(std::move(mesh)), options_(options) {
  const int nn = static_cast<int>(mesh_.nodes.size());
  std::vector<std::pair<int, int>> elementNodes;
  for (const auto& el : mesh_.elements) elementNodes.emplace_back(el.node1, el.node2);
  checkBeamMeshTopology(nn, elementNodes, owner);
  for (size_t e = 0; e < mesh_.elements.size(); ++e) {
    const auto& el = mesh_.elements[e];
    const std::string who = owner + ": element " + std::to_string(e);
    elements_.emplace_back(mesh_.nodes[el.node1], mesh_.nodes[el.node2], el.yHint, el.section, who, options_.theory);
  }

  // ----- nodal invariants (6 coordinates per node, body frame) ---------------------
  // Element e: u0 = s + C x0, N = C S T over its 12 nodal coordinates (s = start).
  const int nd = kNodeDofs * nn;
  FfrInvariants3d nodal;
  nodal.sBar = Mat3X::Zero(3, nd);
  for (int k = 0; k < 3; ++k) nodal.positionShape[k] = Mat3X::Zero(3, nd);
  using Triplets = std::vector<Eigen::Triplet<double>>;
  std::array<Triplets, 9> tS;  // S_kl at 3 k + l
  std::array<Triplets, 9> tR;  // R_kl at 3 k + l
  std::array<Triplets, 3> tH;  // H_i
  Triplets tm, tk, td;
  for (size_t e = 0; e < elements_.size(); ++e) {
    const BeamElement3d& el = elements_[e];
    const auto& T = el.transformation();
    const Mat3& C = el.rotation();
    const Vec3& s = el.start();
    const double m = el.mass();
    const Vec3 cFirst = C * el.firstMoment();  // int rho C x0 dV
    nodal.mass += m;
    nodal.firstMoment += m * s + cFirst;
    // int rho (s + C x0)(s + C x0)^T dV
    nodal.secondMoment += m * s * s.transpose() + s * cFirst.transpose() + cFirst * s.transpose() +
                          C * el.secondMoment() * C.transpose();
    int idx[12];
    for (int a = 0; a < kNodeDofs; ++a) {
      idx[a] = dof(mesh_.elements[e].node1, a);
      idx[a + kNodeDofs] = dof(mesh_.elements[e].node2, a);
    }
    const Eigen::Matrix<double, 3, 12> sb = C * el.sBar() * T;  // int rho N dV
    // positionShape[k] = int rho u0_k N dV = s_k C S-bar T + sum_a C(k, a) C (int rho x0_a S dV) T
    std::array<Eigen::Matrix<double, 3, 12>, 3> ps;
    for (int k = 0; k < 3; ++k) {
      Eigen::Matrix<double, 3, 12> xs = Eigen::Matrix<double, 3, 12>::Zero();
      for (int a = 0; a < 3; ++a) xs += C(k, a) * el.positionShapeIntegral(a);
      ps[k] = s[k] * sb + C * xs * T;
    }
    // a tensor of element matrices in body axes: X_kl = T^T (sum_ab C(k, a) C(l, b) X_ab^e) T
    const auto toBody = [&](auto elementMatrix) {
      std::array<BeamElement3d::Mat12, 9> out;
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          BeamElement3d::Mat12 acc = BeamElement3d::Mat12::Zero();
          for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) acc += (C(k, a) * C(l, b)) * elementMatrix(a, b);
          }
          out[3 * k + l] = T.transpose() * acc * T;
        }
      }
      return out;
    };
    // S_kl = int rho N_k^T N_l dV; R_kl likewise (int rho u2 dV = 0 over each section: no
    // terms from the start s)
    const auto skl = toBody([&](int a, int b) -> const BeamElement3d::Mat12& { return el.sKL(a, b); });
    const auto rkl = toBody([&](int a, int b) -> const BeamElement3d::Mat12& { return el.sectionRotationMoment(a, b); });
    // H_i: int rho u0 x u2 dV = C int rho x0 x u2 dV (+ s x int rho u2 dV = 0): a vector
    std::array<BeamElement3d::Mat12, 3> hi;
    for (int i = 0; i < 3; ++i) {
      BeamElement3d::Mat12 acc = BeamElement3d::Mat12::Zero();
      for (int a = 0; a < 3; ++a) acc += C(i, a) * el.sectionRotationCoupling(a);
      hi[i] = T.transpose() * acc * T;
    }
    const BeamElement3d::Mat12 mm = T.transpose() * el.massMatrix() * T;
    const BeamElement3d::Mat12 kk = T.transpose() * el.stiffness() * T;
    const double beta = el.section().damping;
    for (int a = 0; a < 12; ++a) {
      nodal.sBar.col(idx[a]) += sb.col(a);
      for (int k = 0; k < 3; ++k) nodal.positionShape[k].col(idx[a]) += ps[k].col(a);
      for (int b = 0; b < 12; ++b) {
        // S_kl keep their exact zeros out: an element along a body axis moves its
        // coordinates in one direction each (S_xx has only axial entries), and the body
        // walks the stored entries at every evaluation (issue 24)
        for (int kl = 0; kl < 9; ++kl) {
          if (skl[kl](a, b) != 0.0) tS[kl].emplace_back(idx[a], idx[b], skl[kl](a, b));
          if (rkl[kl](a, b) != 0.0) tR[kl].emplace_back(idx[a], idx[b], rkl[kl](a, b));
          if (kl < 3 && hi[kl](a, b) != 0.0) tH[kl].emplace_back(idx[a], idx[b], hi[kl](a, b));
        }
        tm.emplace_back(idx[a], idx[b], mm(a, b));
        tk.emplace_back(idx[a], idx[b], kk(a, b));
        if (beta > 0.0) td.emplace_back(idx[a], idx[b], beta * kk(a, b));
      }
    }
  }
  auto build = [nd](SpMat& A, const Triplets& t) {
    A.resize(nd, nd);
    A.setFromTriplets(t.begin(), t.end());  // duplicates summed
  };
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      build(nodal.sKL[k][l], tS[3 * k + l]);
      build(nodal.rKL[k][l], tR[3 * k + l]);
    }
    build(nodal.hI[k], tH[k]);
  }
  build(nodal.mff, tm);
  build(nodal.kff, tk);
  build(nodal.dff, td);

  // ----- reference conditions: rows C of C q_n = 0, then B2 = null(C) -------------
  const ReferenceConditions3d& rc = options_.reference;
  auto checkNode = [&](int n, const char* which) {
    if (n < 0 || n >= nn) {
      throw InputError(owner + ": reference " + which + " " + std::to_string(n) + " does not exist (nodes 0.." +
                       std::to_string(nn - 1) + ")");
    }
  };
  MatX C = MatX::Zero(6, nd);
  std::vector<std::string> rowNames;
  switch (rc.type) {
    case ReferenceConditions3d::Type::Clamped: {
      checkNode(rc.nodeA, "node A");
      for (int k = 0; k < kNodeDofs; ++k) {
        C(k, dof(rc.nodeA, k)) = 1.0;
        rowNames.push_back(nodeDofName(dof(rc.nodeA, k)));
      }
      break;
    }
    case ReferenceConditions3d::Type::PinnedPinned: {
      const int a = rc.nodeA, b = rc.nodeB < 0 ? nn - 1 : rc.nodeB;
      checkNode(a, "node A");
      checkNode(b, "node B");
      if (a == b) throw InputError(owner + ": pinned_pinned reference needs two different nodes, got node " +
                                   std::to_string(a) + " twice");
      const Vec3 chord = mesh_.nodes[b] - mesh_.nodes[a];
      const double off = std::hypot(chord.y(), chord.z());
      if (!(chord.x() > 0.0 || chord.x() < 0.0) || off > 1e-9 * chord.norm()) {
        std::ostringstream os;
        os << owner << ": pinned_pinned reference: node " << b << " is not on the body x axis through node " << a
           << " (chord " << chord.transpose() << "); the chord frame needs the mesh placed with the chord A-B "
           << "along the body x axis";
        throw InputError(os.str());
      }
      for (int k = 0; k < 3; ++k) {
        C(k, dof(a, k)) = 1.0;
        rowNames.push_back(nodeDofName(dof(a, k)));
      }
      C(3, dof(b, 1)) = 1.0;
      C(4, dof(b, 2)) = 1.0;
      C(5, dof(a, 3)) = 1.0;
      rowNames.push_back(nodeDofName(dof(b, 1)));
      rowNames.push_back(nodeDofName(dof(b, 2)));
      rowNames.push_back("twist theta_x of node " + std::to_string(a));
      break;
    }
    case ReferenceConditions3d::Type::FreeFree: {
      // int rho u_f dV = S-bar q = 0; int rho u0 x u_f dV = 0, row k of u0 x N:
      // (u0 x N)_x = u0_y N_z - u0_z N_y etc., from the position-shape integrals
      C.topRows(3) = nodal.sBar;
      for (int k = 0; k < 3; ++k) {
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        C.row(3 + k) = nodal.positionShape[i].row(j) - nodal.positionShape[j].row(i);
      }
      rowNames = {"mean-axis x", "mean-axis y", "mean-axis z", "mean-axis rotation x", "mean-axis rotation y",
                  "mean-axis rotation z"};
      break;
    }
  }
  const std::vector<int> dep = dependentRows(C);
  if (!dep.empty()) {
    throw InputError(owner + ": the reference conditions over-constrain the body: condition '" + rowNames[dep[0]] +
                     "' repeats the others");
  }
  SpMat B = sparseNullSpaceBasis(C);

  // ----- modal reduction (bodies/modal_reduction.hpp) -------------------------------
  const std::vector<int> keep = chosenModes(options_.modes, options_.modeSet, owner);
  const bool craigBampton = options_.reduction == ModalReduction::CraigBampton;
  if (!craigBampton && !options_.interfaceNodes.empty()) {
    throw InputError(owner + ": interface nodes are for the craig_bampton reduction only");
  }
  if (options_.inertiaModes && !craigBampton && keep.empty()) {
    throw InputError(owner + ": inertia modes need a modal reduction (modes, or the craig_bampton reduction)");
  }
  if (craigBampton || !keep.empty()) {
    FfrInvariants3d reduced = nodal.transformed(B);
    reduced.validate(owner);  // names a rigid mode left by the reference conditions
    MatX P;
    if (craigBampton) {
      std::vector<int> dofs;
      const MatX G = interfaceConditions(B, kNodeDofs, options_.interfaceNodes, owner, dofs);
      CraigBamptonBasis cb = craigBamptonBasis(reduced.kff, reduced.mff, G, keep, owner);
      for (int r : cb.interfaceRows) constraintDofs_.push_back(dofs[r]);
      fixedInterfaceFrequencies_ = std::move(cb.fixedInterfaceFrequencies);
      P = std::move(cb.basis);
    } else {
      P = normalModes(MatX(reduced.kff), MatX(reduced.mff), keep, owner);  // mass-normalised
    }
    if (options_.inertiaModes) {
      // inertia loads of the frame's rigid motion on q_f at q_f = 0: translation S-bar^T,
      // and int rho N^T (W u0) dV for every 3 x 3 W (alpha~ + omega~ omega~ spans them):
      // the columns int rho N_l^T u0_k = row l of positionShape[k]
      MatX F(reduced.mff.rows(), 12);
      F.leftCols(3) = reduced.sBar.transpose();
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) F.col(3 + 3 * k + l) = reduced.positionShape[k].row(l).transpose();
      }
      const int before = static_cast<int>(P.cols());
      P = withStaticModes(reduced.kff, reduced.mff, P, F);
      numInertiaModes_ = static_cast<int>(P.cols()) - before;
    }
    B = SpMat((B * P).sparseView());
  }
  basis_ = B;
  for (size_t e = 0; e < elements_.size(); ++e) elementBases_.push_back(elementBasis(static_cast<int>(e)));
  invariants_ = nodal.transformed(B);
  invariants_.points.clear();
  for (int n = 0; n < nn; ++n) {
    FfrPoint3d p;
    p.position = mesh_.nodes[n];
    p.shape = MatX(basis_.middleRows(dof(n, 0), 3));
    p.rotationShape = MatX(basis_.middleRows(dof(n, 3), 3));
    invariants_.points.push_back(p);
  }
  invariants_.validate(owner);
}

VecX FfrBeamModel3d::naturalFrequencies() const {
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(MatX(invariants_.kff), MatX(invariants_.mff),
                                                           Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

FfrBeamModel3d::ElementBasis FfrBeamModel3d::elementBasis(int e) const {
  const auto& el = mesh_.elements[e];
  std::array<int, 12> rows;
  for (int a = 0; a < kNodeDofs; ++a) {
    rows[a] = dof(el.node1, a);
    rows[a + kNodeDofs] = dof(el.node2, a);
  }
  return makeElementBasis<12>(basis_, rows);
}

BeamElement3d::Vec12 FfrBeamModel3d::elementCoordinates(int e, const ConstVecRef& qf) const {
  const ElementBasis& eb = elementBases_[e];
  BeamElement3d::Vec12 u = BeamElement3d::Vec12::Zero();  // B q_f over the element's columns
  for (size_t k = 0; k < eb.cols.size(); ++k) u += eb.B.col(static_cast<Eigen::Index>(k)) * qf[eb.cols[k]];
  return elements_[e].transformation() * u;
}

double FfrBeamModel3d::strainEnergy(const VecX& qf) const {
  if (!options_.geometricStiffening) return 0.5 * qf.dot(invariants_.kff * qf);
  double U = 0.0;
  for (size_t e = 0; e < elements_.size(); ++e) U += elements_[e].strainEnergy(elementCoordinates(e, qf), true);
  return U;
}

VecX FfrBeamModel3d::strainEnergyGradient(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff * qf;
  VecX g = VecX::Zero(qf.size());
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const auto& T = elements_[e].transformation();
    const VecX ge = eb.B.transpose() * (T.transpose() * elements_[e].strainEnergyGradient(elementCoordinates(e, qf), true));
    for (size_t k = 0; k < eb.cols.size(); ++k) g[eb.cols[k]] += ge[k];
  }
  return g;
}

SpMat FfrBeamModel3d::strainEnergyHessian(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff;
  std::vector<Eigen::Triplet<double>> t;
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const MatX TB = elements_[e].transformation() * eb.B;
    const MatX He = TB.transpose() * elements_[e].strainEnergyHessian(elementCoordinates(e, qf), true) * TB;
    for (size_t j = 0; j < eb.cols.size(); ++j) {
      for (size_t i = 0; i < eb.cols.size(); ++i) t.emplace_back(eb.cols[i], eb.cols[j], He(i, j));  // all entries: fixed structure
    }
  }
  SpMat H(qf.size(), qf.size());
  H.setFromTriplets(t.begin(), t.end());
  return H;
}

void FfrBeamModel3d::addStrainEnergyGradient(const ConstVecRef& qf, double scale, Eigen::Ref<VecX> out) const {
  if (!options_.geometricStiffening) {
    for (int j = 0; j < invariants_.kff.outerSize(); ++j) {
      for (SpMat::InnerIterator it(invariants_.kff, j); it; ++it) out[it.row()] += scale * it.value() * qf[j];
    }
    return;
  }
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    // dU/dq_f = (T B)^T dU_e/de, e = T B q_f (chain rule over the element's columns)
    const BeamElement3d::Vec12 ge =
        elements_[e].transformation().transpose() * elements_[e].strainEnergyGradient(elementCoordinates(e, qf), true);
    for (size_t k = 0; k < eb.cols.size(); ++k) out[eb.cols[k]] += scale * eb.B.col(static_cast<Eigen::Index>(k)).dot(ge);
  }
}

void FfrBeamModel3d::addStrainEnergyHessian(const ConstVecRef& qf, double scale, const MatrixSink& K, int row0,
                                            int col0) const {
  if (!options_.geometricStiffening) {
    for (int j = 0; j < invariants_.kff.outerSize(); ++j) {
      for (SpMat::InnerIterator it(invariants_.kff, j); it; ++it) K.add(row0 + it.row(), col0 + j, scale * it.value());
    }
    return;
  }
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const auto& T = elements_[e].transformation();
    // d2U/dq_f2 = (T B)^T H_e (T B)
    const BeamElement3d::Mat12 He =
        T.transpose() * elements_[e].strainEnergyHessian(elementCoordinates(e, qf), true) * T;
    const int n = static_cast<int>(eb.cols.size());
    for (int j = 0; j < n; ++j) {
      const BeamElement3d::Vec12 hj = He * eb.B.col(j);
      for (int i = 0; i < n; ++i) K.add(row0 + eb.cols[i], col0 + eb.cols[j], scale * eb.B.col(i).dot(hj));
    }
  }
}

bool FfrBeamModel3d::locate(const Vec3& point, int& element, double& xi) const {
  for (size_t e = 0; e < elements_.size(); ++e) {
    const auto& el = elements_[e];
    const Vec3 local = el.rotation().transpose() * (point - el.start());
    const double tol = 1e-9 * el.length();
    if (std::hypot(local.y(), local.z()) <= tol && local.x() >= -tol && local.x() <= el.length() + tol) {
      element = static_cast<int>(e);
      xi = std::clamp(local.x() / el.length(), 0.0, 1.0);
      return true;
    }
  }
  return false;
}

FfrPoint3d FfrBeamModel3d::materialPoint(int e, double xi) const {
  const BeamElement3d& el = elements_.at(e);
  const Mat3& C = el.rotation();
  const ElementBasis& eb = elementBases_[e];
  const MatX TB = el.transformation() * eb.B;
  const double l = el.length();
  FfrPoint3d p;
  p.position = el.start() + C * Vec3(xi * l, 0.0, 0.0);
  p.shape = Mat3X::Zero(3, numElastic());
  p.rotationShape = Mat3X::Zero(3, numElastic());
  // section rotation in element axes: (tx, ty, tz) (Euler-Bernoulli: twist, -dw_z/dx, dw_y/dx)
  const Mat3X shape = C * BeamElement3d::shape(xi, l, el.shear()) * TB;
  const Mat3X rotation = C * BeamElement3d::rotationShape(xi, l, el.shear()) * TB;
  for (size_t k = 0; k < eb.cols.size(); ++k) {
    p.shape.col(eb.cols[k]) = shape.col(k);
    p.rotationShape.col(eb.cols[k]) = rotation.col(k);
  }
  return p;
}

BeamSectionForces3d FfrBeamModel3d::sectionForces(const VecX& qf, int e, double xi) const {
  const BeamElement3d& el = elements_.at(e);
  return el.sectionForces(elementCoordinates(e, qf), xi, options_.geometricStiffening);
}

}  // namespace flexmbd
