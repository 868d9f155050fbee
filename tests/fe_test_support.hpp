// What the tests of imported FE bodies share (test_fe_import, test_fe_scene,
// test_fe_interfaces, test_calculix, test_sid): the message of an expected InputError and
// the check that it names what it should; the frequencies of a spinning body.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include <initializer_list>
#include <string>

#include "bodies/ffr_body_3d.hpp"
#include "core/errors.hpp"

namespace flexmbd::fetest {

/// The message of the InputError `f` throws (a test failure if it throws none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

/// Every one of `parts` occurs in `msg`.
inline void expectMentions(const std::string& msg, std::initializer_list<std::string> parts) {
  for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

/// The natural frequencies (Hz, ascending) of a body of invariants `inv` linearised about
/// q_f = 0 with its frame spinning steadily at w about its z axis (the frame's motion
/// prescribed, Coriolis terms left out as an FE code's prestressed frequency analysis
/// leaves them): K = -dQ_f/dq_f of the body's own internal forces, M = m_ff.
inline VecX spinningFrequencies(const FfrInvariants3d& inv, double w) {
  const FfrBody3d body("spinning", inv, FrameState3d{});
  const int nf = body.numElastic();
  const VecX q = body.initialCoordinates();
  VecX v = VecX::Zero(6 + nf);
  v[5] = w;
  MatX dQdq = MatX::Zero(6 + nf, 7 + nf), dQdv = MatX::Zero(6 + nf, 6 + nf);
  body.addInternalForceJacobians(q, v, dQdq, dQdv);
  const MatX K = -dQdq.block(6, 7, nf, nf);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> es(0.5 * (K + K.transpose()), MatX(inv.mff));
  return es.eigenvalues().cwiseSqrt() / (2.0 * M_PI);
}

/// The Southwell coefficient (omega^2 - omega0^2) / w^2 of frequencies f (at spin w) and
/// f0 (at rest), Hz.
inline double southwellCoefficient(double f, double f0, double w) {
  return (std::pow(2.0 * M_PI * f, 2) - std::pow(2.0 * M_PI * f0, 2)) / (w * w);
}

/// The first flapwise Southwell coefficient of a uniform cantilever whose root is on the
/// spin axis (hub radius 0): omega^2 = omega0^2 + 1.1933 w^2 out of the plane of rotation,
/// + (1.1933 - 1) w^2 in it (the spin softening). Hodges & Rutkowski 1981 (AIAA J. 19(11)).
constexpr double kSouthwellCantilever = 1.1933;

}  // namespace flexmbd::fetest
