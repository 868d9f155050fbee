// PlanarBeam (bodies/ffr_beam_traits.hpp): what a planar beam model does differently from
// a spatial one. Formulas: docs/flexible-bodies.md.
#include "bodies/ffr_beam_traits.hpp"

#include "core/errors.hpp"

namespace flexmbd {

const char* PlanarBeam::nodeDofName(int k) {
  static const char* names[kNodeDofs] = {"u_x", "u_y", "psi"};
  return names[k];
}

PlanarBeam::Element PlanarBeam::makeElement(const Mesh& mesh, int e, const Options& options, const std::string& who) {
  const auto& el = mesh.elements[e];
  return Element(mesh.nodes[el.node1], mesh.nodes[el.node2], el.section, who, options.theory);
}

PlanarBeam::InertiaAssembly::InertiaAssembly(int numNodalDofs) : nd_(numNodalDofs) {
  nodal_.sBar = Mat2X::Zero(2, nd_);
  nodal_.i1 = VecX::Zero(nd_);
  nodal_.j0 = VecX::Zero(nd_);
}

void PlanarBeam::InertiaAssembly::add(const Element& el, const ElementRows& idx) {
  const auto& T = el.transformation();
  const Mat2 R = rotation(el.angle());
  const Vec2 XA = el.start();
  const Vec2 RtX = R.transpose() * XA;
  const double l = el.length(), rhoA = el.section().massPerLength();
  nodal_.mass += el.mass();
  nodal_.firstMoment += el.mass() * (XA + R * Vec2(0.5 * l, 0.0));
  // int rho |X_A + R [x, y]|^2 dV: the centre line's, plus the sections' own rho I l
  // (Rayleigh, Timoshenko: el.sectionMoment(); zero for Euler-Bernoulli's centre line)
  nodal_.polarMoment +=
      rhoA * (l * XA.squaredNorm() + l * l * XA.dot(R.col(0)) + l * l * l / 3.0) + el.sectionMoment();
  const Eigen::Matrix<double, 2, 6> sb = R * el.sBar() * T;  // int rho N dV, N = R S T (Doc003)
  // int rho N^T u0 = T^T (S-bar^T R^T X_A + int rho (x S_x + y S_y)^T dV)
  const BeamElement2d::Vec6 i1 =
      T.transpose() * (el.sBar().transpose() * RtX + el.sX().row(0).transpose() + el.sY().row(1).transpose());
  // int rho N^T S u0 = T^T (S-bar^T S R^T X_A + int rho (x S_y - y S_x)^T dV)
  const BeamElement2d::Vec6 j0 = T.transpose() * (el.sBar().transpose() * perp(RtX) + el.sX().row(1).transpose() -
                                                  el.sY().row(0).transpose());
  // S~ = T^T (S_xy - S_xy^T) T
  const BeamElement2d::Mat6 st = T.transpose() * (el.sXY() - el.sXY().transpose()) * T;
  const bool turnsSections = el.theory() != BeamTheory::EulerBernoulli;
  const BeamElement2d::Mat6 rr = T.transpose() * el.sectionRotationMoment() * T;  // R = T^T R_el T
  for (int a = 0; a < kElementDofs; ++a) {
    nodal_.sBar.col(idx[a]) += sb.col(a);
    nodal_.i1[idx[a]] += i1[a];
    nodal_.j0[idx[a]] += j0[a];
    for (int b = 0; b < kElementDofs; ++b) {
      tSTilde_.emplace_back(idx[a], idx[b], st(a, b));
      if (turnsSections) tR_.emplace_back(idx[a], idx[b], rr(a, b));
    }
  }
}

PlanarBeam::Invariants PlanarBeam::InertiaAssembly::finish() {
  nodal_.sTilde.resize(nd_, nd_);
  nodal_.sTilde.setFromTriplets(tSTilde_.begin(), tSTilde_.end());  // duplicates summed
  if (!tR_.empty()) {
    nodal_.rff.resize(nd_, nd_);
    nodal_.rff.setFromTriplets(tR_.begin(), tR_.end());
  }
  return std::move(nodal_);
}

void PlanarBeam::pinnedPinnedRows(int a, int b, const Mesh& mesh, MatX& C, std::vector<std::string>& names,
                                  const std::string&) {
  const Vec2 chord = mesh.nodes[b] - mesh.nodes[a];
  const Vec2 n = perp(chord.normalized());
  C(0, kNodeDofs * a + 0) = 1.0;
  C(1, kNodeDofs * a + 1) = 1.0;
  C(2, kNodeDofs * b + 0) = n.x();  // n . u_b = 0: node b stays on the chord
  C(2, kNodeDofs * b + 1) = n.y();
  names = {"u_x of node " + std::to_string(a), "u_y of node " + std::to_string(a),
           "transverse displacement of node " + std::to_string(b)};
}

void PlanarBeam::meanAxisRotationRows(const Invariants& nodal, MatX& C, std::vector<std::string>& names) {
  C.row(2) = nodal.j0.transpose();  // int rho u0 x u_f dV = J0^T q_n (mean axes, Shabana2005, ch. 5)
  names.push_back("mean-axis rotation");
}

MatX PlanarBeam::inertiaLoads(const Invariants& reduced) {
  MatX F(reduced.numElastic(), 4);
  F << reduced.sBar.transpose(), reduced.i1, reduced.j0;
  return F;
}

Eigen::Matrix<double, 2, PlanarBeam::kElementDofs> PlanarBeam::bodyShape(const Element& el, double xi) {
  return rotation(el.angle()) * BeamElement2d::shape(xi, el.length(), el.shear());
}

Eigen::Matrix<double, 1, PlanarBeam::kElementDofs> PlanarBeam::rotationShape(const Element& el, double xi) {
  return BeamElement2d::rotationShape(xi, el.length(), el.shear());  // the section's rotation psi
}

}  // namespace flexmbd
