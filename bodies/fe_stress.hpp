/// @file
/// Stresses of imported FE bodies (docs/fe-import.md "Stresses"): the
/// nodal stress fields an FE code computed for some displacement fields of the body (its
/// modes, its static load cases: CalculiX .frd DISP and STRESS blocks, read by
/// fe_import/fe_calculix.hpp stressSamplesFromFrd) give, by linearity,
/// the stress shape of each coordinate of the reduced body, sigma = S q_f; von Mises of it.
#pragma once

#include <string>

#include "bodies/fe_body_data.hpp"
#include "bodies/fe_body_model.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// Displacement fields of the body and the nodal stresses that go with them.
struct FeStressSamples {
  MatX displacement;  ///< numDofs x k, rows in the matrices' DOF order
  MatX stress;        ///< 6 numNodes x k: node a's sxx, syy, szz, sxy, syz, szx at rows 6 a ..
};

/// The samples of several files side by side.
FeStressSamples joinedSamples(const FeStressSamples& a, const FeStressSamples& b);

/// The stress shapes of the model's coordinates (6 numNodes x nf): each basis column's
/// nodal displacements u (the nodal map times the column) written in the samples,
/// u = D c by least squares (column-pivoting QR), and its stress Sigma c. The residual
/// |D c - u| must not exceed kStressSpanTolerance |u|.
/// @throws InputError naming `owner` and the coordinate whose displacement the samples do
/// not span (e.g. a free-free mode with samples of a clamped analysis).
MatX stressShapes(const FeBodyModel& model, const FeStressSamples& samples, const std::string& owner);

/// The samples print 6 digits (.frd E12.5): a field in their span is written to ~1e-5; one
/// outside misses by a fraction of itself. 1e-3 between the two.
constexpr double kStressSpanTolerance = 1e-3;

/// The von Mises stress of (sxx, syy, szz, sxy, syz, szx):
/// sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2 + 3 (sxy^2 + syz^2 + szx^2)).
double vonMises(const Eigen::Ref<const Eigen::Matrix<double, 6, 1>>& s);

}  // namespace flexmbd
