#include "bodies/ffr_beam_model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <numeric>
#include <sstream>

#include "bodies/modal_reduction.hpp"
#include "bodies/beam_mesh_topology.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"

namespace flexmbd {
namespace {

int dof(int node, int k) { return 3 * node + k; }

std::string nodeDofName(int row) {
  static const char* names[3] = {"u_x", "u_y", "psi"};
  return std::string(names[row % 3]) + " of node " + std::to_string(row / 3);
}

}  // namespace

BeamMesh2d BeamMesh2d::straight(double length, int numElements, const BeamSection& section,
                                const Vec2& origin) {
  if (numElements < 1) throw InputError("beam mesh: elements must be >= 1, got " + std::to_string(numElements));
  requirePositive(length, "beam mesh: length");
  BeamMesh2d m;
  for (int i = 0; i <= numElements; ++i) m.nodes.push_back(origin + Vec2(length * i / numElements, 0.0));
  for (int i = 0; i < numElements; ++i) m.elements.push_back({i, i + 1, section});
  return m;
}

FfrBeamModel::FfrBeamModel(BeamMesh2d mesh, const FfrBeamOptions& options, const std::string& owner)
    : mesh_(std::move(mesh)), options_(options) {
  const int nn = static_cast<int>(mesh_.nodes.size());
  std::vector<std::pair<int, int>> elementNodes;
  for (const auto& el : mesh_.elements) elementNodes.emplace_back(el.node1, el.node2);
  checkBeamMeshTopology(nn, elementNodes, owner);
  for (size_t e = 0; e < mesh_.elements.size(); ++e) {
    const auto& el = mesh_.elements[e];
    const std::string who = owner + ": element " + std::to_string(e);
    elements_.emplace_back(mesh_.nodes[el.node1], mesh_.nodes[el.node2], el.section, who);
  }

  // ----- nodal invariants (3 coordinates per node) --------------------------------
  const int nd = 3 * nn;
  FfrInvariants nodal;
  nodal.sBar = Mat2X::Zero(2, nd);
  nodal.i1 = VecX::Zero(nd);
  nodal.j0 = VecX::Zero(nd);
  std::vector<Eigen::Triplet<double>> tm, ts, tk, td;  // element blocks of m_ff, S~, K_ff, D_ff
  for (size_t e = 0; e < elements_.size(); ++e) {
    const BeamElement2d& el = elements_[e];
    const auto& T = el.transformation();
    const Mat2 R = rotation(el.angle());
    const Vec2 XA = el.start();
    const Vec2 RtX = R.transpose() * XA;
    const double l = el.length(), rhoA = el.section().massPerLength();
    nodal.mass += el.mass();
    nodal.firstMoment += el.mass() * (XA + R * Vec2(0.5 * l, 0.0));
    // int rho |X_A + R [x, 0]|^2 dx
    nodal.polarMoment += rhoA * (l * XA.squaredNorm() + l * l * XA.dot(R.col(0)) + l * l * l / 3.0);
    const int idx[6] = {dof(mesh_.elements[e].node1, 0), dof(mesh_.elements[e].node1, 1), dof(mesh_.elements[e].node1, 2),
                        dof(mesh_.elements[e].node2, 0), dof(mesh_.elements[e].node2, 1), dof(mesh_.elements[e].node2, 2)};
    const Eigen::Matrix<double, 2, 6> sb = R * el.sBar() * T;  // int rho N dV, N = R S T
    // int rho N^T u0 = T^T (S-bar^T R^T X_A + int rho x S_x^T dx)
    const BeamElement2d::Vec6 i1 = T.transpose() * (el.sBar().transpose() * RtX + el.sX().row(0).transpose());
    // int rho N^T S u0 = T^T (S-bar^T S R^T X_A + int rho x S_y^T dx)
    const BeamElement2d::Vec6 j0 = T.transpose() * (el.sBar().transpose() * perp(RtX) + el.sX().row(1).transpose());
    const BeamElement2d::Mat6 m = T.transpose() * (el.sXX() + el.sYY()) * T;
    const BeamElement2d::Mat6 st = T.transpose() * (el.sXY() - el.sXY().transpose()) * T;
    const BeamElement2d::Mat6 k = T.transpose() * el.stiffness() * T;
    for (int a = 0; a < 6; ++a) {
      nodal.sBar.col(idx[a]) += sb.col(a);
      nodal.i1[idx[a]] += i1[a];
      nodal.j0[idx[a]] += j0[a];
      for (int b = 0; b < 6; ++b) {
        tm.emplace_back(idx[a], idx[b], m(a, b));
        ts.emplace_back(idx[a], idx[b], st(a, b));
        tk.emplace_back(idx[a], idx[b], k(a, b));
        if (el.section().damping > 0.0) td.emplace_back(idx[a], idx[b], el.section().damping * k(a, b));
      }
    }
  }
  for (auto [A, t] : {std::pair<SpMat*, const std::vector<Eigen::Triplet<double>>*>{&nodal.mff, &tm},
                      {&nodal.sTilde, &ts}, {&nodal.kff, &tk}, {&nodal.dff, &td}}) {
    A->resize(nd, nd);
    A->setFromTriplets(t->begin(), t->end());  // duplicates summed
  }

  // ----- reference conditions: rows C of C q_n = 0, then B2 = null(C) -------------
  const ReferenceConditions& rc = options_.reference;
  auto checkNode = [&](int n, const char* which) {
    if (n < 0 || n >= nn) {
      throw InputError(owner + ": reference " + which + " " + std::to_string(n) + " does not exist (nodes 0.." +
                       std::to_string(nn - 1) + ")");
    }
  };
  MatX C;
  std::vector<std::string> rowNames;
  switch (rc.type) {
    case ReferenceConditions::Type::PinnedPinned: {
      const int a = rc.nodeA, b = rc.nodeB < 0 ? nn - 1 : rc.nodeB;
      checkNode(a, "node");
      checkNode(b, "node");
      if (a == b) throw InputError(owner + ": pinned_pinned reference needs two different nodes");
      const Vec2 chord = mesh_.nodes[b] - mesh_.nodes[a];
      const Vec2 n = perp(chord.normalized());
      C = MatX::Zero(3, nd);
      C(0, dof(a, 0)) = 1.0;
      C(1, dof(a, 1)) = 1.0;
      C(2, dof(b, 0)) = n.x();
      C(2, dof(b, 1)) = n.y();
      rowNames = {"u_x of node " + std::to_string(a), "u_y of node " + std::to_string(a),
                  "transverse displacement of node " + std::to_string(b)};
      break;
    }
    case ReferenceConditions::Type::Clamped: {
      checkNode(rc.nodeA, "node");
      C = MatX::Zero(3, nd);
      for (int k = 0; k < 3; ++k) {
        C(k, dof(rc.nodeA, k)) = 1.0;
        rowNames.push_back(nodeDofName(dof(rc.nodeA, k)));
      }
      break;
    }
    case ReferenceConditions::Type::FreeFree: {
      C = MatX::Zero(3, nd);
      C.topRows(2) = nodal.sBar;           // int rho u_f dV = 0
      C.row(2) = nodal.j0.transpose();     // int rho u0 x u_f dV = 0 (mean axis)
      rowNames = {"mean-axis x", "mean-axis y", "mean-axis rotation"};
      break;
    }
  }
  const std::vector<int> dep = dependentRows(C);
  if (!dep.empty()) {
    throw InputError(owner + ": the reference conditions over-constrain the body: condition '" + rowNames[dep[0]] +
                     "' repeats the others");
  }
  // B2 keeps unit columns where it can: sparse for the pinned and clamped conditions
  SpMat B = nullSpaceBasis(C).sparseView(1.0, 1e-14);

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
    FfrInvariants reduced = nodal.transformed(B);
    reduced.validate(owner);  // names a rigid mode left by the reference conditions
    MatX P;
    if (craigBampton) {
      std::vector<int> dofs;
      const MatX G = interfaceConditions(B, 3, options_.interfaceNodes, owner, dofs);
      CraigBamptonBasis cb = craigBamptonBasis(reduced.kff, reduced.mff, G, keep, owner);
      for (int r : cb.interfaceRows) constraintDofs_.push_back(dofs[r]);
      fixedInterfaceFrequencies_ = std::move(cb.fixedInterfaceFrequencies);
      P = std::move(cb.basis);
    } else {
      P = normalModes(MatX(reduced.kff), MatX(reduced.mff), keep, owner);  // mass-normalised
    }
    if (options_.inertiaModes) {
      // inertia loads of the frame's rigid motion on q_f at q_f = 0 (Q_v, Q_g in
      // docs/flexible-bodies.md): translation S-bar^T, centrifugal I1, angular J0
      MatX F(reduced.numElastic(), 4);
      F << reduced.sBar.transpose(), reduced.i1, reduced.j0;
      const int before = static_cast<int>(P.cols());
      P = withStaticModes(reduced.kff, reduced.mff, P, F);
      numInertiaModes_ = static_cast<int>(P.cols()) - before;
    }
    B = (B * P).sparseView();
  }
  basis_ = B;
  for (size_t e = 0; e < elements_.size(); ++e) elementBases_.push_back(elementBasis(static_cast<int>(e)));
  invariants_ = nodal.transformed(B);
  invariants_.points.clear();
  for (int n = 0; n < nn; ++n) {
    FfrPoint p;
    p.position = mesh_.nodes[n];
    p.shape = MatX(basis_.middleRows(dof(n, 0), 2));
    p.rotationShape = MatX(basis_.row(dof(n, 2)));
    invariants_.points.push_back(p);
  }
  invariants_.validate(owner);
}

VecX FfrBeamModel::naturalFrequencies() const {
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(MatX(invariants_.kff), MatX(invariants_.mff),
                                                           Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

FfrBeamModel::ElementBasis FfrBeamModel::elementBasis(int e) const {
  const auto& el = mesh_.elements[e];
  return makeElementBasis<6>(basis_, {dof(el.node1, 0), dof(el.node1, 1), dof(el.node1, 2), dof(el.node2, 0),
                                      dof(el.node2, 1), dof(el.node2, 2)});
}

BeamElement2d::Vec6 FfrBeamModel::elementCoordinates(int e, const ElementBasis& eb, const VecX& qf) const {
  VecX ql(eb.cols.size());
  for (size_t k = 0; k < eb.cols.size(); ++k) ql[k] = qf[eb.cols[k]];
  return elements_[e].transformation() * (eb.B * ql);
}

double FfrBeamModel::strainEnergy(const VecX& qf) const {
  if (!options_.geometricStiffening) return 0.5 * qf.dot(invariants_.kff * qf);
  double U = 0.0;
  for (size_t e = 0; e < elements_.size(); ++e) {
    U += elements_[e].strainEnergy(elementCoordinates(e, elementBases_[e], qf), true);
  }
  return U;
}

VecX FfrBeamModel::strainEnergyGradient(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff * qf;
  VecX g = VecX::Zero(qf.size());
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const auto& T = elements_[e].transformation();
    const VecX ge = eb.B.transpose() * (T.transpose() * elements_[e].strainEnergyGradient(elementCoordinates(e, eb, qf), true));
    for (size_t k = 0; k < eb.cols.size(); ++k) g[eb.cols[k]] += ge[k];
  }
  return g;
}

SpMat FfrBeamModel::strainEnergyHessian(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff;
  std::vector<Eigen::Triplet<double>> t;
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const MatX TB = elements_[e].transformation() * eb.B;
    const MatX He = TB.transpose() * elements_[e].strainEnergyHessian(elementCoordinates(e, eb, qf), true) * TB;
    for (size_t j = 0; j < eb.cols.size(); ++j) {
      for (size_t i = 0; i < eb.cols.size(); ++i) t.emplace_back(eb.cols[i], eb.cols[j], He(i, j));  // all entries: fixed structure
    }
  }
  SpMat H(qf.size(), qf.size());
  H.setFromTriplets(t.begin(), t.end());
  return H;
}

bool FfrBeamModel::locate(const Vec2& point, int& element, double& xi) const {
  for (size_t e = 0; e < elements_.size(); ++e) {
    const auto& el = elements_[e];
    const Vec2 local = rotation(el.angle()).transpose() * (point - el.start());
    const double tol = 1e-9 * el.length();
    if (std::abs(local.y()) <= tol && local.x() >= -tol && local.x() <= el.length() + tol) {
      element = static_cast<int>(e);
      xi = std::clamp(local.x() / el.length(), 0.0, 1.0);
      return true;
    }
  }
  return false;
}

FfrPoint FfrBeamModel::materialPoint(int e, double xi) const {
  const BeamElement2d& el = elements_.at(e);
  const Mat2 R = rotation(el.angle());
  const ElementBasis& eb = elementBases_[e];
  const MatX TB = el.transformation() * eb.B;
  FfrPoint p;
  p.position = el.start() + R * Vec2(xi * el.length(), 0.0);
  p.shape = Mat2X::Zero(2, numElastic());
  p.rotationShape = RowVecX::Zero(numElastic());
  const Mat2X shape = R * BeamElement2d::shape(xi, el.length()) * TB;
  const RowVecX slope = BeamElement2d::slopeShape(xi, el.length()) * TB;
  for (size_t k = 0; k < eb.cols.size(); ++k) {
    p.shape.col(eb.cols[k]) = shape.col(k);
    p.rotationShape[eb.cols[k]] = slope[k];
  }
  return p;
}

Vec2 FfrBeamModel::sectionForces(const VecX& qf, int e, double xi) const {
  const BeamElement2d& el = elements_.at(e);
  return el.sectionForces(elementCoordinates(e, elementBases_[e], qf), xi, options_.geometricStiffening);
}

}  // namespace flexmbd
