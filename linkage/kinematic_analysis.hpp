/// @file
/// Kinematic analysis of a planar linkage by the deformation-parameter method of source
/// Doc000 (after VanDerWerff1977): transfer functions,
/// Taylor predictor and Newton corrector on the exact deformation parameters, velocities
/// and accelerations, and detection of singular positions (lock, dead and change points).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "linkage/linkage_2d.hpp"

namespace flexmbd {

enum class CorrectorKind {
  Newton,          ///< D L1 at every iterate: quadratic convergence (default)
  ModifiedNewton,  ///< D L1 of the reference position, as in the document's flowchart (Fig. 3)
};

struct KinematicSettings {
  double start = 0.0;              ///< alpha at step 0 (the initial geometry)
  double end = 2.0 * M_PI;         ///< alpha at the last step
  int steps = 60;                  ///< number of input steps (>= 1)
  double speed = 1.0;              ///< alphadot at every step (Doc000, eqs. 24-25)
  double acceleration = 0.0;       ///< alphaddot at every step
  double tolerance = 1e-13;        ///< max |eps| to reach (length units: eps2,3 carry l0)
  int maxIterations = 50;          ///< corrector iterations per step
  CorrectorKind corrector = CorrectorKind::Newton;
  /// A position whose D L1 (columns scaled to unit max norm) has a reciprocal condition
  /// number below this is singular.
  double singularTolerance = 1e-10;
  /// Width of the bracket [alpha_ok, alpha_fail] to which a singular position is located.
  double locateTolerance = 1e-10;
  /// @throws InputError naming the setting that is out of range.
  void validate() const;
};

/// The linkage at one input position.
struct KinematicState {
  int step = 0;
  double alpha = 0.0;
  VecX x;      ///< coordinates (Linkage2d::coordinateNames())
  VecX xp;     ///< first-order transfer functions dX/dalpha (Doc000, eq. 22)
  VecX xpp;    ///< second-order transfer functions d2X/dalpha2 (Doc000, eq. 23)
  VecX v;      ///< dX/dt = X' alphadot (Doc000, eq. 24)
  VecX a;      ///< d2X/dt2 = X'' alphadot^2 + X' alphaddot (Doc000, eq. 25)
  int iterations = 0;      ///< corrector iterations (step 0: those of the assembly)
  double residual = 0.0;   ///< max |eps| at the converged position
  double rcond = 0.0;      ///< reciprocal condition number of the scaled D L1
};

/// A singular D L1 met during the run.
struct SingularPosition {
  double alpha = 0.0;              ///< best estimate (midpoint of the bracket)
  double alphaRegular = 0.0;       ///< last alpha with a regular position
  double alphaBeyond = 0.0;        ///< first alpha tried beyond it
  std::string kind;                ///< "lock" (no position beyond) or "change point" (branches cross)
  std::vector<std::string> nodes;  ///< nodes that move in the singular mode or lie on its links
  std::vector<std::string> links;  ///< links that turn in the singular mode
};

struct KinematicSummary {
  bool ok = true;
  std::string message;
  int stepsCompleted = 0;          ///< states passed to the callback (step 0 included)
  double alphaReached = 0.0;
  int assemblyIterations = 0;
  int minIterations = 0, maxIterations = 0;  ///< over steps 1..N
  double meanIterations = 0.0;
  double maxResidual = 0.0;        ///< over all states
  double wallSeconds = 0.0;       ///< wall-clock time of run()
  std::optional<SingularPosition> singular;
};

/// The analysis of one linkage. The constructor assembles the linkage at alpha = start
/// (Newton on the exact deformation parameters from the given node positions).
class KinematicAnalysis {
 public:
  /// @throws InputError if the settings are invalid or the linkage is not finalized;
  ///         ModelError if it cannot be assembled or is singular at the start.
  KinematicAnalysis(const Linkage2d& linkage, const KinematicSettings& settings);

  const Linkage2d& linkage() const { return linkage_; }
  const KinematicSettings& settings() const { return settings_; }
  /// Assembled coordinates at alpha = start.
  const VecX& startCoordinates() const { return x0_; }
  int assemblyIterations() const { return assemblyIterations_; }

  /// Values of the input coordinates at alpha.
  VecX inputValues(double alpha) const;

  struct Correction {
    bool converged = false;
    int iterations = 0;   ///< corrections applied
    double residual = 0;  ///< max |eps| at the end
  };
  /// Sets the inputs of X to their values at alpha and corrects the unknowns, u* =
  /// -(D L1)^-1 zeta (Doc000, eq. 27), until max |eps| <= tolerance. `frozen`: D L1 to use at
  /// every iteration (modified Newton); null: D L1 at every iterate.
  Correction correct(double alpha, VecX& X, const MatX* frozen = nullptr) const;

  struct TransferFunctions {
    VecX first, second;
    double rcond = 0.0;       ///< of D L1, columns scaled to unit max norm
    int determinantSign = 0;  ///< sign of det(D L1) (0: exactly singular)
  };
  /// X' = L1 x'1 + L2 x'2 with x'1 = -(D L1)^-1 D L2 x'2 (Doc000, eq. 22), and
  /// X'' with x''1 = -(D L1)^-1 (dD/dalpha) X' (Doc000, eq. 23, x''2 = 0: the inputs are affine
  /// in alpha). Meaningful only when rcond is not tiny.
  TransferFunctions transferFunctions(const VecX& X) const;

  /// The converged state at alpha, corrected from `guess`. @throws ModelError if the
  /// corrector does not converge.
  KinematicState solve(double alpha, const VecX& guess) const;

  /// Steps alpha from start to end (settings.steps steps): Taylor predictor (Doc000, eq. 26),
  /// corrector (Doc000, eqs. 27-28), transfer functions, velocities and accelerations; every
  /// state goes to onStep. A singular position stops the run: it is located, reported
  /// in the summary (ok = false), and the states up to it have been passed on.
  KinematicSummary run(const std::function<void(const KinematicState&)>& onStep) const;

  /// D L1 (unknown columns) of the linkage at X.
  MatX unknownJacobian(const VecX& X) const;

 private:
  KinematicState makeState(int step, double alpha, const VecX& X, const Correction& c) const;
  SingularPosition locate(const KinematicState& regular, double alphaBeyond, bool lockSuspected) const;
  void describeSingularMode(const VecX& X, SingularPosition& s) const;

  const Linkage2d& linkage_;
  KinematicSettings settings_;
  VecX x0_;
  int assemblyIterations_ = 0;
};

/// The columns of a kinematic analysis's table (kinematics.csv): step, alpha, iterations,
/// residual, rcond; each input; per node x, y, dx_da, dy_da, d2x_da2, d2y_da2, vx, vy,
/// ax, ay; per link angle, dangle_da, d2angle_da2, omega, omega_dot.
std::vector<std::string> kinematicsColumns(const Linkage2d& linkage);
/// One state's row in kinematicsColumns' order, into `values` (cleared).
void kinematicsRow(const Linkage2d& linkage, const KinematicState& s, std::vector<double>& values);

/// Convenience: KinematicAnalysis(linkage, settings).run(onStep).
KinematicSummary analyzeKinematics(const Linkage2d& linkage, const KinematicSettings& settings,
                                   const std::function<void(const KinematicState&)>& onStep);

}  // namespace flexmbd
