/// @file
/// What the tensegrity integrators report: samples at output times, events (snaps,
/// slack and taut transitions, contacts) and a summary of the run.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// State at one output time. Vectors are full (every node coordinate, fixed ones too).
struct TensegritySample {
  double t = 0.0;
  long steps = 0;  ///< steps taken up to this sample (the summary's "steps" of a run stopped here)
  VecX x, v;
  VecX cableTension;   ///< method 1: impulse of the last step / dt; method 2: elastic law
  VecX cableImpulse;   ///< method 1: sum of snap impulses since the previous sample; method 2: 0
  VecX cableLength;
  std::vector<bool> slack;  ///< cable shorter than its natural length (beyond the slack tolerance)
  double kineticEnergy = 0.0, potentialEnergy = 0.0;
};

struct TensegrityEvent {
  enum class Type {
    Snap,     ///< slack (or unloaded) cable jerked taut with an impulse (method 1)
    Taut,     ///< cable reaches its natural length without impulse
    Slack,    ///< cable goes slack
    Contact,  ///< two members come within the sum of their radii
  };
  Type type = Type::Snap;
  double t = 0.0;
  long step = 0;                  ///< time step (method 1) or CVODE step count (method 2)
  std::string member, other;      ///< the cable; for contacts the two members
  double impulse = 0.0;           ///< Snap: the tension impulse
  double elongationRate = 0.0;    ///< Snap: elongation rate of the cable before the impact
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< Contact: midpoint of the closest points
  double energyChange = 0.0;      ///< Snap: total energy after - before the step
};
std::string toString(TensegrityEvent::Type type);

struct TensegrityRunSummary {
  bool ok = true;
  std::string message;
  std::string method;  ///< "time_stepping" or "massless_cables"
  double tReached = 0.0;
  long steps = 0;
  double cpuSeconds = 0.0;
  int snaps = 0, tautTransitions = 0, slackTransitions = 0, contacts = 0;
  /// Adds the event to its counter.
  void count(const TensegrityEvent& e) {
    switch (e.type) {
      case TensegrityEvent::Type::Snap: ++snaps; break;
      case TensegrityEvent::Type::Taut: ++tautTransitions; break;
      case TensegrityEvent::Type::Slack: ++slackTransitions; break;
      case TensegrityEvent::Type::Contact: ++contacts; break;
    }
  }
  double energyStart = 0.0, energyEnd = 0.0;
  /// Method 1: largest increase of total energy over a step containing a snap (<= 0 expected).
  double maxEnergyIncreaseAtSnap = -1e300;
  /// Method 1: largest (l - l0)/l0 of an inextensible cable before and after projection.
  double maxDriftBeforeProjection = 0.0, maxDriftAfterProjection = 0.0;
  long projectionIterations = 0;
  double maxLcpResidual = 0.0;
  int maxLcpSize = 0;
  long lcpIterations = 0;
  double contactImpulseSum = 0.0;  ///< method 1 with contact constraints: sum of contact impulses
  long lcpSolves = 0;   ///< method 1: LCPs of the impulses solved (projection LCPs not counted)
  long lcpSizeSum = 0;  ///< method 1: sum of their sizes (mean size = lcpSizeSum / lcpSolves)
  std::string lcpSolver;
  /// Method 2: CVODE statistics.
  long rhsEvals = 0, rootEvals = 0, errorTestFailures = 0, nonlinearConvFailures = 0;
};

class TensegrityStructure;

/// The columns of a tensegrity run's results table (results.csv): t; every node's
/// coordinates "<node>.x", ".y" (".z"); their velocities "<node>.vx", ...; per strut
/// ".force" (N = EA (l - l0) / l0, tension positive; Doc001), ".length"; per cable ".tension",
/// ".slack" (0/1), ".impulse", ".length"; energy.kinetic, energy.potential, energy.total.
std::vector<std::string> tensegrityColumns(const TensegrityStructure& s);
/// One sample's row in tensegrityColumns' order, into `values` (cleared).
/// @throws NonFiniteResult naming the quantity and the time if a value is not finite.
void tensegrityRow(const TensegrityStructure& s, const TensegritySample& sample, std::vector<double>& values);

struct TensegrityObserver {
  std::function<void(const TensegritySample&)> onSample;  ///< may be empty
  std::function<void(const TensegrityEvent&)> onEvent;    ///< may be empty
};

}  // namespace flexmbd
