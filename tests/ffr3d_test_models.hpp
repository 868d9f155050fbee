// Test-local spatial FFR invariants assembled directly from BeamElement3d, an oracle
// independent of bodies/ffr_beam_model_3d (test FfrBody3d.ChainOracleEqualsTheBeamModel
// checks that the two agree): a chain
// of elements clamped at node 0 (its six coordinates dropped), body-frame sums of the
// element integrals with u0 = start + C x0 and N = C S T L (L selects the element's
// coordinates among the body's).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "bodies/ffr_invariants_3d.hpp"
#include "elements/beam_element_3d.hpp"
#include "elements/beam_section.hpp"

namespace flexmbd::test3d {

struct BeamChain3d {
  std::vector<BeamElement3d> elements;
  std::vector<Vec3> nodes;
  int nf = 0;
  FfrInvariants3d inv;
  /// L (12 x nf): element e's coordinates from the body's (node 0 clamped).
  MatX selection(int e) const {
    MatX L = MatX::Zero(12, nf);
    for (int end = 0; end < 2; ++end) {
      const int node = e + end;
      if (node == 0) continue;
      L.block(6 * end, 6 * (node - 1), 6, 6).setIdentity();
    }
    return L;
  }
  /// N (3 x nf) of the material point (xi, y, z) of element e (element frame).
  Mat3X pointShape(int e, double xi, double y, double z) const {
    const BeamElement3d& el = elements[e];
    return el.rotation() * BeamElement3d::pointShape(xi, y, z, el.length(), el.theory(), el.shear()) * el.transformation() *
           selection(e);
  }
  /// The section rotation phi = Phi q_f (3 x nf, element axes) at xi of element e.
  Mat3X sectionRotation(int e, double xi) const {
    const BeamElement3d& el = elements[e];
    return BeamElement3d::sectionRotationShape(xi, el.length(), el.theory(), el.shear()) * el.transformation() * selection(e);
  }
  /// u0 (body frame) of that point.
  Vec3 pointPosition(int e, double xi, double y, double z) const {
    const BeamElement3d& el = elements[e];
    return el.start() + el.rotation() * Vec3(xi * el.length(), y, z);
  }
};

/// Elements between consecutive nodes (>= 2 nodes), all with the same section and y hint.
inline BeamChain3d makeBeamChain(const std::vector<Vec3>& nodes, const BeamSection3d& section, const Vec3& yHint,
                                 double stiffnessScale = 1.0, BeamTheory theory = BeamTheory::EulerBernoulli) {
  BeamChain3d c;
  c.nodes = nodes;
  const int ne = static_cast<int>(nodes.size()) - 1;
  c.nf = 6 * ne;
  const int nf = c.nf;
  for (int e = 0; e < ne; ++e) c.elements.emplace_back(nodes[e], nodes[e + 1], yHint, section, "test chain", theory);
  FfrInvariants3d& inv = c.inv;
  inv.sBar = Mat3X::Zero(3, nf);
  MatX mff = MatX::Zero(nf, nf), kff = MatX::Zero(nf, nf);
  std::array<std::array<MatX, 3>, 3> skl, rkl;
  std::array<MatX, 3> hi = {MatX::Zero(nf, nf), MatX::Zero(nf, nf), MatX::Zero(nf, nf)};
  for (int k = 0; k < 3; ++k) {
    inv.positionShape[k] = Mat3X::Zero(3, nf);
    for (int l = 0; l < 3; ++l) skl[k][l] = rkl[k][l] = MatX::Zero(nf, nf);
  }
  for (int e = 0; e < ne; ++e) {
    const BeamElement3d& el = c.elements[e];
    const Mat3& C = el.rotation();
    const Vec3& s0 = el.start();
    const MatX TL = el.transformation() * c.selection(e);  // 12 x nf
    const double m = el.mass();
    const Vec3 cf = C * el.firstMoment();
    inv.mass += m;
    inv.firstMoment += m * s0 + cf;
    inv.secondMoment += m * s0 * s0.transpose() + s0 * cf.transpose() + cf * s0.transpose() +
                        C * el.secondMoment() * C.transpose();
    const Mat3X sb = C * el.sBar() * TL;  // int rho N dV
    inv.sBar += sb;
    for (int k = 0; k < 3; ++k) {
      // int rho u0_k N dV = s0_k int rho N dV + sum_a C_ka C int rho x0_a S dV T L
      Mat3X pk = s0[k] * sb;
      for (int a = 0; a < 3; ++a) pk += C(k, a) * C * el.positionShapeIntegral(a) * TL;
      inv.positionShape[k] += pk;
      BeamElement3d::Mat12 h = BeamElement3d::Mat12::Zero();  // H_k = sum_a C_ka H_a^e
      for (int a = 0; a < 3; ++a) h += C(k, a) * el.sectionRotationCoupling(a);
      hi[k] += TL.transpose() * h * TL;
      for (int l = 0; l < 3; ++l) {
        // N_k = sum_a C_ka S_a T L:  S_kl = (T L)^T (sum_ab C_ka C_lb S_ab) T L
        BeamElement3d::Mat12 s = BeamElement3d::Mat12::Zero();
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) s += C(k, a) * C(l, b) * el.sKL(a, b);
        skl[k][l] += TL.transpose() * s * TL;
        BeamElement3d::Mat12 r = BeamElement3d::Mat12::Zero();  // R_kl likewise
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) r += C(k, a) * C(l, b) * el.sectionRotationMoment(a, b);
        rkl[k][l] += TL.transpose() * r * TL;
      }
    }
    mff += TL.transpose() * el.massMatrix() * TL;
    kff += stiffnessScale * TL.transpose() * el.stiffness() * TL;
  }
  // exact symmetries (round-off of the sums): S_lk = S_kl^T
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      const MatX s = (k == l) ? MatX(0.5 * (skl[k][k] + skl[k][k].transpose())) : MatX(skl[k][l]);
      inv.sKL[k][l] = s.sparseView(0.0, 0.0);
      // R_kl: symmetric, R_lk = R_kl (round-off of the sums)
      const MatX r = 0.25 * (rkl[k][l] + rkl[k][l].transpose() + rkl[l][k] + rkl[l][k].transpose());
      inv.rKL[k][l] = r.sparseView(0.0, 0.0);
    }
  }
  for (int k = 0; k < 3; ++k)
    for (int l = k + 1; l < 3; ++l) inv.sKL[l][k] = SpMat(inv.sKL[k][l].transpose());
  mff = 0.5 * (mff + mff.transpose());
  kff = 0.5 * (kff + kff.transpose());
  inv.mff = mff.sparseView(0.0, 0.0);
  inv.kff = kff.sparseView(0.0, 0.0);
  inv.dff = (section.damping * kff).sparseView(0.0, 0.0);
  for (auto* S : {&inv.mff, &inv.kff, &inv.dff}) S->makeCompressed();
  for (auto& row : inv.sKL)
    for (auto& S : row) S.makeCompressed();
  for (auto& row : inv.rKL)
    for (auto& R : row) R.makeCompressed();
  for (int k = 0; k < 3; ++k) {
    inv.hI[k] = MatX(0.5 * (hi[k] + hi[k].transpose())).sparseView(0.0, 0.0);
    inv.hI[k].makeCompressed();
  }
  for (int n = 0; n < ne + 1; ++n) {
    FfrPoint3d p;
    p.position = nodes[n];
    p.shape = Mat3X::Zero(3, nf);
    p.rotationShape = Mat3X::Zero(3, nf);
    if (n > 0) {
      p.shape.middleCols(6 * (n - 1), 3).setIdentity();
      p.rotationShape.middleCols(6 * (n - 1) + 3, 3).setIdentity();
    }
    inv.points.push_back(p);
  }
  return c;
}

/// The standard test body: three elements of a 3 cm x 1.8 cm steel bar, bent in space,
/// node 0 (clamped) off the frame origin.
inline std::vector<Vec3> bentNodes() {
  const Vec3 p0(0.05, -0.02, 0.01);
  const Vec3 p1 = p0 + 0.4 * Vec3(1.0, 0.2, 0.1).normalized();
  const Vec3 p2 = p1 + 0.35 * Vec3(0.3, 1.0, -0.2).normalized();
  const Vec3 p3 = p2 + 0.3 * Vec3(-0.2, 0.4, 1.0).normalized();
  return {p0, p1, p2, p3};
}

}  // namespace flexmbd::test3d
