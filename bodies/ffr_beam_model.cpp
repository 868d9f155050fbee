// FfrBeamModelT (bodies/ffr_beam_model.hpp): the beam-model code planar and spatial
// bodies share; what differs is in PlanarBeam and SpatialBeam (bodies/ffr_beam_traits.hpp).
#include "bodies/ffr_beam_model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "bodies/beam_mesh_topology.hpp"
#include "bodies/modal_reduction.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/memory_budget.hpp"

namespace flexmbd {

template <class Traits>
FfrBeamModelT<Traits>::FfrBeamModelT(Mesh mesh, const Options& options, const std::string& owner)
    : mesh_(std::move(mesh)), options_(options) {
  if (static_cast<long>(mesh_.elements.size()) > kMaxElements) {
    throw InputError(owner + ": " + std::to_string(mesh_.elements.size()) + " elements, more than the " +
                     std::to_string(kMaxElements) + " a beam body may have (docs/stability.md, \"Sizes\")");
  }
  requireMemory(memoryEstimate(), owner, "this beam model and a run of it");
  buildElements(owner);
  const Invariants nodal = nodalInvariants();
  const SpMat B2 = sparseNullSpaceBasis(referenceConditions(nodal, owner));  // unit columns where it can
  setBasis(reduced(B2, nodal, owner), nodal, owner);
}

template <class Traits>
double FfrBeamModelT<Traits>::memoryEstimate() const {
  // Without a reduction every node keeps a dense kNodeDofs x nf block of shapes (its point
  // in the invariants), nf ~ N = kNodeDofs x nodes: 8 N^2 bytes; the run's Jacobian
  // factors and the output's accelerations take about 2.5 times as much again (measured on
  // 100 to 1,000 spatial elements: docs/stability.md, "Sizes"). A modal reduction solves
  // a dense eigenproblem of K and M over N: about six N x N matrices at once.
  const double N = static_cast<double>(mesh_.nodes.size()) * kNodeDofs;
  const bool modal = !options_.modeSet.empty() || options_.modes > 0 ||
                     options_.reduction == ModalReduction::CraigBampton;
  return modal ? 6.0 * 8.0 * N * N : 3.5 * 8.0 * N * N;
}

template <class Traits>
void FfrBeamModelT<Traits>::buildElements(const std::string& owner) {
  std::vector<std::pair<int, int>> elementNodes;
  for (const auto& el : mesh_.elements) elementNodes.emplace_back(el.node1, el.node2);
  checkBeamMeshTopology(static_cast<int>(mesh_.nodes.size()), elementNodes, owner);
  for (size_t e = 0; e < mesh_.elements.size(); ++e) {
    const std::string who = owner + ": element " + std::to_string(e);
    elements_.push_back(Traits::makeElement(mesh_, static_cast<int>(e), options_, who));
  }
}

template <class Traits>
typename Traits::ElementRows FfrBeamModelT<Traits>::elementRows(int e) const {
  const auto& el = mesh_.elements[e];
  typename Traits::ElementRows rows;
  for (int a = 0; a < kNodeDofs; ++a) {
    rows[a] = dof(el.node1, a);
    rows[a + kNodeDofs] = dof(el.node2, a);
  }
  return rows;
}

template <class Traits>
typename Traits::Invariants FfrBeamModelT<Traits>::nodalInvariants() const {
  const int nd = kNodeDofs * static_cast<int>(mesh_.nodes.size());
  typename Traits::InertiaAssembly inertia(nd);
  Triplets tm, tk, td;  // element blocks of m_ff, K_ff, D_ff
  for (size_t e = 0; e < elements_.size(); ++e) {
    const Element& el = elements_[e];
    const auto idx = elementRows(static_cast<int>(e));
    inertia.add(el, idx);
    const auto& T = el.transformation();
    const ElementMatrix m = T.transpose() * Traits::elementMass(el) * T;  // body axes: T^T M T
    const ElementMatrix k = T.transpose() * el.stiffness() * T;
    const double beta = el.section().damping;  // D = beta K
    for (int a = 0; a < kElementDofs; ++a) {
      for (int b = 0; b < kElementDofs; ++b) {
        tm.emplace_back(idx[a], idx[b], m(a, b));
        tk.emplace_back(idx[a], idx[b], k(a, b));
        if (beta > 0.0) td.emplace_back(idx[a], idx[b], beta * k(a, b));
      }
    }
  }
  Invariants nodal = inertia.finish();
  for (auto [A, t] : {std::pair<SpMat*, const Triplets*>{&nodal.mff, &tm}, {&nodal.kff, &tk}, {&nodal.dff, &td}}) {
    A->resize(nd, nd);
    A->setFromTriplets(t->begin(), t->end());  // duplicates summed
  }
  return nodal;
}

template <class Traits>
MatX FfrBeamModelT<Traits>::referenceConditions(const Invariants& nodal, const std::string& owner) const {
  using Type = typename ReferenceConditionsT<Traits::kDim>::Type;
  const auto& rc = options_.reference;
  const int nn = static_cast<int>(mesh_.nodes.size());
  const auto checkNode = [&](int n, char which) {
    if (n < 0 || n >= nn) {
      throw InputError(owner + ": reference " + Traits::referenceNodeName(which) + " " + std::to_string(n) +
                       " does not exist (nodes 0.." + std::to_string(nn - 1) + ")");
    }
  };
  const auto nodeDofName = [](int row) {
    return std::string(Traits::nodeDofName(row % kNodeDofs)) + " of node " + std::to_string(row / kNodeDofs);
  };
  MatX C = MatX::Zero(kNodeDofs, kNodeDofs * nn);  // as many conditions as a node has coordinates
  std::vector<std::string> rowNames;
  switch (rc.type) {
    case Type::PinnedPinned: {
      const int a = rc.nodeA, b = rc.nodeB < 0 ? nn - 1 : rc.nodeB;
      checkNode(a, 'A');
      checkNode(b, 'B');
      if (a == b) {
        throw InputError(owner + ": pinned_pinned reference needs two different nodes, got node " +
                         std::to_string(a) + " twice");
      }
      Traits::pinnedPinnedRows(a, b, mesh_, C, rowNames, owner);
      break;
    }
    case Type::Clamped: {
      checkNode(rc.nodeA, 'A');
      for (int k = 0; k < kNodeDofs; ++k) {
        C(k, dof(rc.nodeA, k)) = 1.0;
        rowNames.push_back(nodeDofName(dof(rc.nodeA, k)));
      }
      break;
    }
    case Type::FreeFree: {
      // mean-axis conditions (Shabana2005, ch. 5):
      C.topRows(Traits::kDim) = nodal.sBar;  // int rho u_f dV = S-bar q_n = 0
      for (int k = 0; k < Traits::kDim; ++k) rowNames.push_back(std::string("mean-axis ") + "xyz"[k]);
      Traits::meanAxisRotationRows(nodal, C, rowNames);  // int rho u0 x u_f dV = 0 (Shabana2005, ch. 5)
      break;
    }
  }
  const std::vector<int> dep = dependentRows(C);
  if (!dep.empty()) {
    throw InputError(owner + ": the reference conditions over-constrain the body: condition '" + rowNames[dep[0]] +
                     "' repeats the others");
  }
  return C;
}

template <class Traits>
SpMat FfrBeamModelT<Traits>::reduced(SpMat B, const Invariants& nodal, const std::string& owner) {
  const std::vector<int> keep = chosenModes(options_.modes, options_.modeSet, owner);
  const bool craigBampton = options_.reduction == ModalReduction::CraigBampton;
  if (!craigBampton && !options_.interfaceNodes.empty()) {
    throw InputError(owner + ": interface nodes are for the craig_bampton reduction only");
  }
  if (options_.inertiaModes && !craigBampton && keep.empty()) {
    throw InputError(owner + ": inertia modes need a modal reduction (modes, or the craig_bampton reduction)");
  }
  if (!craigBampton && keep.empty()) return B;
  Invariants onB2 = nodal.transformed(B);
  onB2.validate(owner);  // names a rigid mode left by the reference conditions
  MatX P;
  if (craigBampton) {
    std::vector<int> dofs;
    const MatX G = interfaceConditions(B, kNodeDofs, options_.interfaceNodes, owner, dofs);
    CraigBamptonBasis cb = craigBamptonBasis(onB2.kff, onB2.mff, G, keep, owner);
    for (int r : cb.interfaceRows) constraintDofs_.push_back(dofs[r]);
    fixedInterfaceFrequencies_ = std::move(cb.fixedInterfaceFrequencies);
    P = std::move(cb.basis);
  } else {
    P = normalModes(MatX(onB2.kff), MatX(onB2.mff), keep, owner);  // mass-normalised
  }
  if (options_.inertiaModes) {
    const int before = static_cast<int>(P.cols());
    P = withStaticModes(onB2.kff, onB2.mff, P, Traits::inertiaLoads(onB2));
    numInertiaModes_ = static_cast<int>(P.cols()) - before;
  }
  return SpMat((B * P).sparseView());
}

template <class Traits>
void FfrBeamModelT<Traits>::setBasis(const SpMat& B, const Invariants& nodal, const std::string& owner) {
  basis_ = B;
  for (size_t e = 0; e < elements_.size(); ++e) {
    const auto rows = elementRows(static_cast<int>(e));
    elementBases_.push_back(makeElementBasis<kElementDofs>(basis_, rows));
  }
  invariants_ = nodal.transformed(B);
  invariants_.points.clear();
  constexpr int rotations = MaterialPoint::kRotations;
  for (int n = 0; n < static_cast<int>(mesh_.nodes.size()); ++n) {
    MaterialPoint p;
    p.position = mesh_.nodes[n];
    p.shape = MatX(basis_.middleRows(dof(n, 0), Traits::kDim));
    p.rotationShape = MatX(basis_.middleRows(dof(n, Traits::kDim), rotations));
    invariants_.points.push_back(p);
  }
  invariants_.validate(owner);
}

template <class Traits>
VecX FfrBeamModelT<Traits>::naturalFrequencies() const {
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(MatX(invariants_.kff), MatX(invariants_.mff),
                                                           Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

template <class Traits>
typename Traits::ElementVector FfrBeamModelT<Traits>::elementCoordinates(int e, const ConstVecRef& qf) const {
  const ElementBasis& eb = elementBases_[e];
  ElementVector u = ElementVector::Zero();  // B q_f over the element's columns
  for (size_t k = 0; k < eb.cols.size(); ++k) u += eb.B.col(static_cast<Eigen::Index>(k)) * qf[eb.cols[k]];
  return elements_[e].transformation() * u;
}

template <class Traits>
double FfrBeamModelT<Traits>::strainEnergy(const VecX& qf) const {
  if (!options_.geometricStiffening) return 0.5 * qf.dot(invariants_.kff * qf);
  double U = 0.0;
  for (size_t e = 0; e < elements_.size(); ++e) U += elements_[e].strainEnergy(elementCoordinates(e, qf), true);
  return U;
}

template <class Traits>
VecX FfrBeamModelT<Traits>::strainEnergyGradient(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff * qf;
  VecX g = VecX::Zero(qf.size());
  addStrainEnergyGradient(qf, 1.0, g);
  return g;
}

template <class Traits>
SpMat FfrBeamModelT<Traits>::strainEnergyHessian(const VecX& qf) const {
  if (!options_.geometricStiffening) return invariants_.kff;
  std::vector<Eigen::Triplet<double>> t;
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    const MatX TB = elements_[e].transformation() * eb.B;
    // d2U/dq_f2 = (T B)^T H_e (T B)
    const MatX He = TB.transpose() * elements_[e].strainEnergyHessian(elementCoordinates(e, qf), true) * TB;
    for (size_t j = 0; j < eb.cols.size(); ++j) {
      for (size_t i = 0; i < eb.cols.size(); ++i) t.emplace_back(eb.cols[i], eb.cols[j], He(i, j));  // all entries: fixed structure
    }
  }
  SpMat H(qf.size(), qf.size());
  H.setFromTriplets(t.begin(), t.end());
  return H;
}

template <class Traits>
void FfrBeamModelT<Traits>::addStrainEnergyGradient(const ConstVecRef& qf, double scale, Eigen::Ref<VecX> out) const {
  if (!options_.geometricStiffening) {
    for (int j = 0; j < invariants_.kff.outerSize(); ++j) {
      for (SpMat::InnerIterator it(invariants_.kff, j); it; ++it) out[it.row()] += scale * it.value() * qf[j];
    }
    return;
  }
  for (size_t e = 0; e < elements_.size(); ++e) {
    const ElementBasis& eb = elementBases_[e];
    // dU/dq_f = (T B)^T dU_e/de, e = T B q_f (chain rule over the element's columns)
    const ElementVector ge =
        elements_[e].transformation().transpose() * elements_[e].strainEnergyGradient(elementCoordinates(e, qf), true);
    for (size_t k = 0; k < eb.cols.size(); ++k) out[eb.cols[k]] += scale * eb.B.col(static_cast<Eigen::Index>(k)).dot(ge);
  }
}

template <class Traits>
void FfrBeamModelT<Traits>::addStrainEnergyHessian(const ConstVecRef& qf, double scale, const MatrixSink& K, int row0,
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
    const ElementMatrix He = T.transpose() * elements_[e].strainEnergyHessian(elementCoordinates(e, qf), true) * T;
    const int n = static_cast<int>(eb.cols.size());
    for (int j = 0; j < n; ++j) {
      const ElementVector hj = He * eb.B.col(j);
      for (int i = 0; i < n; ++i) K.add(row0 + eb.cols[i], col0 + eb.cols[j], scale * eb.B.col(i).dot(hj));
    }
  }
}

template <class Traits>
bool FfrBeamModelT<Traits>::locate(const Point& point, int& element, double& xi) const {
  for (size_t e = 0; e < elements_.size(); ++e) {
    const auto& el = elements_[e];
    const Point local = Traits::axisRotation(el).transpose() * (point - el.start());  // element axes
    const double tol = 1e-9 * el.length();
    if (Traits::distanceFromAxis(local) <= tol && local.x() >= -tol && local.x() <= el.length() + tol) {
      element = static_cast<int>(e);
      xi = std::clamp(local.x() / el.length(), 0.0, 1.0);
      return true;
    }
  }
  return false;
}

template <class Traits>
typename FfrBeamModelT<Traits>::MaterialPoint FfrBeamModelT<Traits>::materialPoint(int e, double xi) const {
  const Element& el = elements_.at(e);
  const ElementBasis& eb = elementBases_[e];
  const MatX TB = el.transformation() * eb.B;
  MaterialPoint p;
  p.position = el.start() + Traits::axisRotation(el) * (Point::UnitX() * (xi * el.length()));  // start + R [x, 0]
  p.shape = decltype(p.shape)::Zero(Traits::kDim, numElastic());
  p.rotationShape = decltype(p.rotationShape)::Zero(MaterialPoint::kRotations, numElastic());
  const MatX shape = Traits::bodyShape(el, xi) * TB;  // R S(xi) T B over the element's columns
  const MatX rotation = Traits::rotationShape(el, xi) * TB;
  for (size_t k = 0; k < eb.cols.size(); ++k) {
    p.shape.col(eb.cols[k]) = shape.col(k);
    p.rotationShape.col(eb.cols[k]) = rotation.col(k);
  }
  return p;
}

template <class Traits>
typename Traits::SectionForces FfrBeamModelT<Traits>::sectionForces(const VecX& qf, int e, double xi) const {
  return elements_.at(e).sectionForces(elementCoordinates(e, qf), xi, options_.geometricStiffening);
}

template class FfrBeamModelT<PlanarBeam>;
template class FfrBeamModelT<SpatialBeam>;

}  // namespace flexmbd
