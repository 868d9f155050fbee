// SpatialBeam (bodies/ffr_beam_traits.hpp): what a spatial beam model does differently
// from a planar one. Formulas: docs/spatial-flexible.md.
#include "bodies/ffr_beam_traits.hpp"

#include <sstream>

#include "core/errors.hpp"

namespace flexmbd {

const char* SpatialBeam::nodeDofName(int k) {
  static const char* names[kNodeDofs] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};
  return names[k];
}

SpatialBeam::Element SpatialBeam::makeElement(const Mesh& mesh, int e, const Options& options,
                                              const std::string& who) {
  const auto& el = mesh.elements[e];
  return Element(mesh.nodes[el.node1], mesh.nodes[el.node2], el.yHint, el.section, who, options.theory);
}

SpatialBeam::InertiaAssembly::InertiaAssembly(int numNodalDofs) : nd_(numNodalDofs) {
  nodal_.sBar = Mat3X::Zero(3, nd_);
  for (int k = 0; k < 3; ++k) nodal_.positionShape[k] = Mat3X::Zero(3, nd_);
}

// Element el: u0 = s + C x0, N = C S T over its 12 nodal coordinates (s = start; Doc003).
void SpatialBeam::InertiaAssembly::add(const Element& el, const ElementRows& idx) {
  using Mat12 = BeamElement3d::Mat12;
  const auto& T = el.transformation();
  const Mat3& C = el.rotation();
  const Vec3& s = el.start();
  const double m = el.mass();
  const Vec3 cFirst = C * el.firstMoment();  // int rho C x0 dV
  nodal_.mass += m;
  nodal_.firstMoment += m * s + cFirst;
  // int rho (s + C x0)(s + C x0)^T dV
  nodal_.secondMoment += m * s * s.transpose() + s * cFirst.transpose() + cFirst * s.transpose() +
                         C * el.secondMoment() * C.transpose();
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
    std::array<Mat12, 9> out;
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) {
        Mat12 acc = Mat12::Zero();
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
  const auto skl = toBody([&](int a, int b) -> const Mat12& { return el.sKL(a, b); });
  const auto rkl = toBody([&](int a, int b) -> const Mat12& { return el.sectionRotationMoment(a, b); });
  // H_i: int rho u0 x u2 dV = C int rho x0 x u2 dV (+ s x int rho u2 dV = 0): a vector
  std::array<Mat12, 3> hi;
  for (int i = 0; i < 3; ++i) {
    Mat12 acc = Mat12::Zero();
    for (int a = 0; a < 3; ++a) acc += C(i, a) * el.sectionRotationCoupling(a);
    hi[i] = T.transpose() * acc * T;
  }
  for (int a = 0; a < kElementDofs; ++a) {
    nodal_.sBar.col(idx[a]) += sb.col(a);
    for (int k = 0; k < 3; ++k) nodal_.positionShape[k].col(idx[a]) += ps[k].col(a);
    for (int b = 0; b < kElementDofs; ++b) {
      // S_kl keep their exact zeros out: an element along a body axis moves its
      // coordinates in one direction each (S_xx has only axial entries), and the body
      // walks the stored entries at every evaluation
      for (int kl = 0; kl < 9; ++kl) {
        if (skl[kl](a, b) != 0.0) tS_[kl].emplace_back(idx[a], idx[b], skl[kl](a, b));
        if (rkl[kl](a, b) != 0.0) tR_[kl].emplace_back(idx[a], idx[b], rkl[kl](a, b));
        if (kl < 3 && hi[kl](a, b) != 0.0) tH_[kl].emplace_back(idx[a], idx[b], hi[kl](a, b));
      }
    }
  }
}

SpatialBeam::Invariants SpatialBeam::InertiaAssembly::finish() {
  auto build = [this](SpMat& A, const Triplets& t) {
    A.resize(nd_, nd_);
    A.setFromTriplets(t.begin(), t.end());  // duplicates summed
  };
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      build(nodal_.sKL[k][l], tS_[3 * k + l]);
      build(nodal_.rKL[k][l], tR_[3 * k + l]);
    }
    build(nodal_.hI[k], tH_[k]);
  }
  return std::move(nodal_);
}

void SpatialBeam::pinnedPinnedRows(int a, int b, const Mesh& mesh, MatX& C, std::vector<std::string>& names,
                                   const std::string& owner) {
  const Vec3 chord = mesh.nodes[b] - mesh.nodes[a];
  const double off = std::hypot(chord.y(), chord.z());
  if (!(chord.x() > 0.0 || chord.x() < 0.0) || off > 1e-9 * chord.norm()) {
    std::ostringstream os;
    os << owner << ": pinned_pinned reference: node " << b << " is not on the body x axis through node " << a
       << " (chord " << chord.transpose() << "); the chord frame needs the mesh placed with the chord A-B "
       << "along the body x axis";
    throw InputError(os.str());
  }
  const auto dof = [](int node, int k) { return kNodeDofs * node + k; };
  for (int k = 0; k < 3; ++k) {
    C(k, dof(a, k)) = 1.0;
    names.push_back(std::string(nodeDofName(k)) + " of node " + std::to_string(a));
  }
  C(3, dof(b, 1)) = 1.0;
  C(4, dof(b, 2)) = 1.0;
  C(5, dof(a, 3)) = 1.0;
  names.push_back(std::string(nodeDofName(1)) + " of node " + std::to_string(b));
  names.push_back(std::string(nodeDofName(2)) + " of node " + std::to_string(b));
  names.push_back("twist theta_x of node " + std::to_string(a));
}

void SpatialBeam::meanAxisRotationRows(const Invariants& nodal, MatX& C, std::vector<std::string>& names) {
  // int rho u0 x u_f dV = 0 (mean axes, Shabana2005, ch. 5), row k of u0 x N:
  // (u0 x N)_x = u0_y N_z - u0_z N_y etc., from the position-shape integrals
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    C.row(3 + k) = nodal.positionShape[i].row(j) - nodal.positionShape[j].row(i);
  }
  for (const char* axis : {"x", "y", "z"}) names.push_back(std::string("mean-axis rotation ") + axis);
}

MatX SpatialBeam::inertiaLoads(const Invariants& reduced) { return reduced.inertiaLoads(); }

Eigen::Matrix<double, 3, SpatialBeam::kElementDofs> SpatialBeam::bodyShape(const Element& el, double xi) {
  return el.rotation() * BeamElement3d::shape(xi, el.length(), el.shear());
}

Eigen::Matrix<double, 3, SpatialBeam::kElementDofs> SpatialBeam::rotationShape(const Element& el, double xi) {
  // section rotation in element axes: (tx, ty, tz) (Euler-Bernoulli: twist, -dw_z/dx, dw_y/dx)
  return el.rotation() * BeamElement3d::rotationShape(xi, el.length(), el.shear());
}

}  // namespace flexmbd
