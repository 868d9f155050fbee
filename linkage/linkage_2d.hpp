/// @file
/// A planar linkage assembled from rigid link elements (Doc000): nodes
/// (fixed, free, or sliding along a line), links between them, and the prescribed
/// input coordinates. The model of the kinematic analysis (linkage/kinematic_analysis).
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"
#include "linkage/link_element_2d.hpp"

namespace flexmbd {

using NodeIndex = TypedIndex<struct LinkageNodeTag>;
using LinkIndex = TypedIndex<struct LinkTag>;
using InputIndex = TypedIndex<struct LinkageInputTag>;

/// Coordinates of the linkage, stacked in one vector X (the x of Doc000):
///   - a free node: x, y (2 coordinates);
///   - a slider node: s, its displacement along its line, position r = r0 + s d with d
///     the unit direction (1 coordinate: Doc000's eq. 29 prescribes v3 = 0 for a
///     slider on the x axis, which is the same thing);
///   - a fixed node: none;
///   - every link: the orientation angles beta1, beta2 of the link at its two ends
///     (Doc000, eq. 2; each link end has its own angle, so links meeting at a node are hinged).
/// Every link contributes three deformation parameters that must vanish; the mobility
/// is (number of coordinates) - 3 (number of links), and exactly that many inputs must
/// be prescribed. Inputs are coordinates, each an affine function of the one input
/// parameter alpha: X_k(alpha) = X_k(alpha_start) + ratio_k (alpha - alpha_start).
///
/// Build phase: add*, then finalize() checks the model and freezes it.
class Linkage2d {
 public:
  enum class NodeKind { Fixed, Free, Slider };
  enum class InputKind { LinkAngle, SliderPosition, NodeX, NodeY };

  struct Node {
    std::string name;
    NodeKind kind = NodeKind::Free;
    Vec2 position = Vec2::Zero();   ///< initial position (the slider's line passes through it)
    Vec2 direction = Vec2::UnitX(); ///< slider: unit direction of the line
    int offset = -1;                ///< first coordinate in X (after finalize; -1 if fixed)
  };
  struct Link {
    std::string name;
    NodeIndex nodes[2];
    LinkElement2d element;
    int offset = -1;                ///< index of beta1 in X; beta2 follows
  };
  struct Input {
    std::string name;
    InputKind kind = InputKind::LinkAngle;
    LinkIndex link;                 ///< LinkAngle
    NodeIndex node;                 ///< LinkAngle: the end; others: the node
    double ratio = 1.0;             ///< dX_k / dalpha
    int coordinate = -1;            ///< index in X (after finalize)
  };

  // ----- build phase -------------------------------------------------------------
  /// @throws InputError if the name is empty or taken, or a number is not finite.
  NodeIndex addFixedNode(const std::string& name, const Vec2& position);
  NodeIndex addFreeNode(const std::string& name, const Vec2& position);
  /// A node that moves along the line through `position` with direction `direction`
  /// (non-zero; normalised here).
  NodeIndex addSliderNode(const std::string& name, const Vec2& position, const Vec2& direction);
  /// A rigid link; length <= 0 (default): the distance of the nodes' initial positions.
  /// @throws InputError if a node is unknown, both ends are the same node, or the length
  ///         is zero (coincident nodes) or not finite.
  LinkIndex addLink(const std::string& name, const std::string& node1, const std::string& node2,
                    double length = 0.0);
  /// Prescribes the orientation angle of `link` at its end `node` (default: its first
  /// node). For a rigid link this is the absolute angle of the link.
  InputIndex addLinkAngleInput(const std::string& name, const std::string& link, const std::string& node = "",
                               double ratio = 1.0);
  /// Prescribes the displacement s of a slider node along its line.
  InputIndex addSliderInput(const std::string& name, const std::string& node, double ratio = 1.0);
  /// Prescribes the x (axis 0) or y (axis 1) coordinate of a free node.
  InputIndex addNodeCoordinateInput(const std::string& name, const std::string& node, int axis,
                                    double ratio = 1.0);

  /// Checks connectivity (every node on a link, every link connected to a fixed or
  /// slider node), the mobility against the number of inputs, and builds the index maps.
  /// @throws InputError with a one-line message naming what is wrong.
  void finalize();
  bool isFinalized() const { return finalized_; }

  // ----- queries -----------------------------------------------------------------
  int numNodes() const { return static_cast<int>(nodes_.size()); }
  int numLinks() const { return static_cast<int>(links_.size()); }
  int numInputs() const { return static_cast<int>(inputs_.size()); }
  const Node& node(NodeIndex i) const { return nodes_.at(i.value); }
  const Link& link(LinkIndex i) const { return links_.at(i.value); }
  const Input& input(InputIndex i) const { return inputs_.at(i.value); }
  /// @throws InputError listing the known names.
  NodeIndex findNode(const std::string& name) const;
  LinkIndex findLink(const std::string& name) const;

  // ----- after finalize ----------------------------------------------------------
  int numCoordinates() const { return nx_; }
  int numDeformations() const { return 3 * numLinks(); }
  /// (number of coordinates) - 3 (number of links).
  int mobility() const { return nx_ - numDeformations(); }
  /// Initial coordinates: node positions as given, link end angles = chord angles.
  VecX initialCoordinates() const;
  /// Indices of the unknown (L1) and prescribed (L2, the inputs, in input order)
  /// coordinates.
  const std::vector<int>& unknownCoordinates() const { return unknown_; }
  const std::vector<int>& inputCoordinates() const { return prescribed_; }
  /// dX_2 / dalpha: the ratios of the inputs (x'^2 of Doc000, eq. 22).
  VecX inputRates() const;
  /// "O2.x", "O3.s", "crank.beta1", ... for every coordinate.
  std::vector<std::string> coordinateNames() const;

  /// The six element coordinates of a link taken from X (node positions via the node
  /// maps, end angles from X).
  LinkElement2d::Vec6 elementCoordinates(LinkIndex i, const VecX& X) const;
  /// World position of a node, and its derivative along dX (velocity / transfer
  /// function); node positions are affine in X, so the second derivative along X' with
  /// X'' is nodeDerivative(i, X'').
  Vec2 nodePosition(NodeIndex i, const VecX& X) const;
  Vec2 nodeDerivative(NodeIndex i, const VecX& dX) const;

  /// All deformation parameters eps(X) (3 per link, link order).
  VecX deformations(const VecX& X) const;
  /// D(X) = d eps / d X (numDeformations x numCoordinates, dense).
  MatX jacobian(const VecX& X) const;
  /// (dD/dalpha) X' = [X'^T H_k X']_k (Doc000, eq. 23: its dD/dalpha applied to X').
  VecX secondDerivative(const VecX& X, const VecX& dX) const;

 private:
  void requireBuildPhase(const char* what) const;
  void requireFinalized(const char* what) const;
  void checkNewName(const std::string& name, const std::string& kind) const;
  NodeIndex addNode(Node n);
  InputIndex addInput(Input in);
  /// d r / d X_local of a node (2 x 2 free, 2 x 1 slider, 2 x 0 fixed).
  Mat2X nodeMap(NodeIndex i) const;

  std::vector<Node> nodes_;
  std::vector<Link> links_;
  std::vector<Input> inputs_;
  bool finalized_ = false;
  int nx_ = 0;
  std::vector<int> unknown_, prescribed_;
};

}  // namespace flexmbd
