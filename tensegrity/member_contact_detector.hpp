/// @file
/// Contact between tensegrity members (cylinders of given radius around their axes)
/// during a run: segment-segment closest points (tensegrity/segment_closest_points.hpp)
/// and a continuous check between two states, with the node positions moving linearly
/// in between, by conservative advancement. Members sharing a node are never checked.
#pragma once

#include <vector>

#include "tensegrity/tensegrity_output.hpp"
#include "tensegrity/tensegrity_structure.hpp"

namespace flexmbd {

class MemberContactDetector {
 public:
  /// @pre structure finalized; it must outlive the detector.
  explicit MemberContactDetector(const TensegrityStructure& structure);

  /// Number of member pairs checked (pairs that share no node).
  int numPairs() const { return static_cast<int>(pairs_.size()); }

  /// Marks the pairs in contact at (t, x) and reports them.
  void start(double t, const VecX& x, std::vector<TensegrityEvent>& out);

  /// Continuous check over [t0, t1], positions x0 -> x1 linearly. Reports each pair at
  /// the first instant it comes within r_a + r_b (to `tolerance` in distance); a pair
  /// is reported again only after it has separated.
  void advance(double t0, const VecX& x0, double t1, const VecX& x1, std::vector<TensegrityEvent>& out);

  double tolerance() const { return tolerance_; }

 private:
  struct Pair {
    MemberRef a, b;
    int ai, aj, bi, bj;  ///< node indices
    double reach;        ///< r_a + r_b
    bool inContact = false;
  };
  Eigen::Vector3d nodePoint(const VecX& x, int node) const;

  const TensegrityStructure& s_;
  std::vector<Pair> pairs_;
  double tolerance_;
};

}  // namespace flexmbd
