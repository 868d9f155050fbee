#include "linkage/linkage_2d.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>

#include "core/errors.hpp"
#include "core/magnitude_checks.hpp"
#include "core/number_text.hpp"

namespace flexmbd {
namespace {

void requireFiniteVec(const Vec2& v, const std::string& what) {
  if (!std::isfinite(v.x()) || !std::isfinite(v.y())) {
    throw InputError(what + " must be finite numbers, got [" + fmt(v.x()) + ", " + fmt(v.y()) + "]");
  }
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

void Linkage2d::requireBuildPhase(const char* what) const {
  if (finalized_) throw InputError(std::string("linkage: ") + what + " after finalize()");
}

void Linkage2d::requireFinalized(const char* what) const {
  if (!finalized_) throw InputError(std::string("linkage: ") + what + " needs finalize() first");
}

void Linkage2d::checkNewName(const std::string& name, const std::string& kind) const {
  if (name.empty()) throw InputError("linkage: a " + kind + " needs a non-empty name");
  auto taken = [&](const std::string& other) { return other == name; };
  if (kind == "node") {
    for (const auto& n : nodes_) {
      if (taken(n.name)) throw InputError("node " + quoted(name) + " is defined twice (node names must be unique)");
    }
  } else if (kind == "link") {
    for (const auto& l : links_) {
      if (taken(l.name)) throw InputError("link " + quoted(name) + " is defined twice (link names must be unique)");
    }
  } else {
    for (const auto& in : inputs_) {
      if (taken(in.name)) throw InputError("input " + quoted(name) + " is defined twice (input names must be unique)");
    }
  }
}

NodeIndex Linkage2d::addNode(Node n) {
  requireBuildPhase("adding a node");
  checkNewName(n.name, "node");
  requireFiniteVec(n.position, "node " + quoted(n.name) + ": position");
  nodes_.push_back(std::move(n));
  return NodeIndex(numNodes() - 1);
}

NodeIndex Linkage2d::addFixedNode(const std::string& name, const Vec2& position) {
  Node n;
  n.name = name;
  n.kind = NodeKind::Fixed;
  n.position = position;
  return addNode(std::move(n));
}

NodeIndex Linkage2d::addFreeNode(const std::string& name, const Vec2& position) {
  Node n;
  n.name = name;
  n.kind = NodeKind::Free;
  n.position = position;
  return addNode(std::move(n));
}

NodeIndex Linkage2d::addSliderNode(const std::string& name, const Vec2& position, const Vec2& direction) {
  requireFiniteVec(direction, "node " + quoted(name) + ": direction");
  Node n;
  n.name = name;
  n.kind = NodeKind::Slider;
  n.position = position;
  n.direction = unitDirection(direction, "node " + quoted(name) + ": the slider direction");
  return addNode(std::move(n));
}

NodeIndex Linkage2d::findNode(const std::string& name) const {
  std::string known;
  for (int i = 0; i < numNodes(); ++i) {
    if (nodes_[i].name == name) return NodeIndex(i);
    known += (known.empty() ? "" : ", ") + nodes_[i].name;
  }
  throw InputError("unknown node " + quoted(name) + " (known nodes: " + (known.empty() ? "none" : known) + ")");
}

LinkIndex Linkage2d::findLink(const std::string& name) const {
  std::string known;
  for (int i = 0; i < numLinks(); ++i) {
    if (links_[i].name == name) return LinkIndex(i);
    known += (known.empty() ? "" : ", ") + links_[i].name;
  }
  throw InputError("unknown link " + quoted(name) + " (known links: " + (known.empty() ? "none" : known) + ")");
}

LinkIndex Linkage2d::addLink(const std::string& name, const std::string& node1, const std::string& node2,
                             double length) {
  requireBuildPhase("adding a link");
  checkNewName(name, "link");
  const std::string where = "link " + quoted(name);
  NodeIndex a, b;
  try {
    a = findNode(node1);
    b = findNode(node2);
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  if (a == b) throw InputError(where + ": both ends are node " + quoted(node1) + " (expected two different nodes)");
  if (!std::isfinite(length)) throw InputError(where + ": length must be a finite number, got " + fmt(length));
  const double distance = (nodes_[b.value].position - nodes_[a.value].position).norm();
  if (length <= 0.0) {
    if (!(distance > 0.0)) {
      throw InputError(where + ": zero length (nodes " + quoted(node1) + " and " + quoted(node2) +
                       " are at the same position and no length is given)");
    }
    length = distance;
  }
  Link l{name, {a, b}, LinkElement2d(length, name), -1};
  links_.push_back(std::move(l));
  return LinkIndex(numLinks() - 1);
}

InputIndex Linkage2d::addInput(Input in) {
  requireBuildPhase("adding an input");
  checkNewName(in.name, "input");
  if (!std::isfinite(in.ratio)) {
    throw InputError("input " + quoted(in.name) + ": ratio must be a finite number, got " + fmt(in.ratio));
  }
  for (const auto& other : inputs_) {
    if (other.kind == in.kind && other.node == in.node && other.link == in.link) {
      throw InputError("input " + quoted(in.name) + " prescribes the same coordinate as input " +
                       quoted(other.name));
    }
  }
  inputs_.push_back(std::move(in));
  return InputIndex(numInputs() - 1);
}

InputIndex Linkage2d::addLinkAngleInput(const std::string& name, const std::string& link, const std::string& node,
                                        double ratio) {
  Input in;
  in.name = name;
  in.kind = InputKind::LinkAngle;
  in.ratio = ratio;
  try {
    in.link = findLink(link);
    const Link& l = links_[in.link.value];
    in.node = node.empty() ? l.nodes[0] : findNode(node);
    if (in.node != l.nodes[0] && in.node != l.nodes[1]) {
      throw InputError("node " + quoted(node) + " is not an end of link " + quoted(link) + " (its ends: " +
                       nodes_[l.nodes[0].value].name + ", " + nodes_[l.nodes[1].value].name + ")");
    }
  } catch (const InputError& e) {
    throw InputError("input " + quoted(name) + ": " + e.what());
  }
  return addInput(std::move(in));
}

InputIndex Linkage2d::addSliderInput(const std::string& name, const std::string& node, double ratio) {
  Input in;
  in.name = name;
  in.kind = InputKind::SliderPosition;
  in.ratio = ratio;
  try {
    in.node = findNode(node);
  } catch (const InputError& e) {
    throw InputError("input " + quoted(name) + ": " + e.what());
  }
  if (nodes_[in.node.value].kind != NodeKind::Slider) {
    throw InputError("input " + quoted(name) + ": node " + quoted(node) + " is not a slider node");
  }
  return addInput(std::move(in));
}

InputIndex Linkage2d::addNodeCoordinateInput(const std::string& name, const std::string& node, int axis,
                                             double ratio) {
  if (axis != 0 && axis != 1) throw InputError("input " + quoted(name) + ": axis must be 0 (x) or 1 (y)");
  Input in;
  in.name = name;
  in.kind = axis == 0 ? InputKind::NodeX : InputKind::NodeY;
  in.ratio = ratio;
  try {
    in.node = findNode(node);
  } catch (const InputError& e) {
    throw InputError("input " + quoted(name) + ": " + e.what());
  }
  if (nodes_[in.node.value].kind != NodeKind::Free) {
    throw InputError("input " + quoted(name) + ": node " + quoted(node) +
                     " is not a free node (only a free node's x or y can be prescribed)");
  }
  return addInput(std::move(in));
}

void Linkage2d::finalize() {
  requireBuildPhase("finalize()");
  if (links_.empty()) throw InputError("linkage: no links (expected at least one)");

  // Connectivity: every node on a link; every link connected, through links, to a
  // fixed or slider node (the ground).
  std::vector<std::vector<int>> linksAt(nodes_.size());
  for (int k = 0; k < numLinks(); ++k) {
    for (NodeIndex n : links_[k].nodes) linksAt[n.value].push_back(k);
  }
  for (int i = 0; i < numNodes(); ++i) {
    if (linksAt[i].empty()) {
      throw InputError("node " + quoted(nodes_[i].name) + " is not connected to any link");
    }
  }
  std::vector<char> grounded(nodes_.size(), 0);
  std::vector<int> stack;
  for (int i = 0; i < numNodes(); ++i) {
    if (nodes_[i].kind != NodeKind::Free) {
      grounded[i] = 1;
      stack.push_back(i);
    }
  }
  if (stack.empty()) {
    throw InputError("linkage: no fixed or slider node (the mechanism is not connected to the ground)");
  }
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    for (int k : linksAt[i]) {
      for (NodeIndex n : links_[k].nodes) {
        if (!grounded[n.value]) {
          grounded[n.value] = 1;
          stack.push_back(n.value);
        }
      }
    }
  }
  for (const Link& l : links_) {
    if (!grounded[l.nodes[0].value]) {
      throw InputError("link " + quoted(l.name) + " is disconnected: no chain of links joins it to a fixed or " +
                       "slider node (its nodes: " + nodes_[l.nodes[0].value].name + ", " +
                       nodes_[l.nodes[1].value].name + ")");
    }
  }

  // Index maps.
  int k = 0;
  for (Node& n : nodes_) {
    n.offset = n.kind == NodeKind::Fixed ? -1 : k;
    k += n.kind == NodeKind::Free ? 2 : (n.kind == NodeKind::Slider ? 1 : 0);
  }
  for (Link& l : links_) {
    l.offset = k;
    k += 2;
  }
  nx_ = k;

  const int m = mobility();
  if (m <= 0) {
    throw InputError("linkage: mobility " + std::to_string(m) + " (" + std::to_string(nx_) + " coordinates - 3 x " +
                     std::to_string(numLinks()) + " links): a structure, not a mechanism; nothing can be driven");
  }
  if (numInputs() != m) {
    throw InputError("linkage: mobility " + std::to_string(m) + " (" + std::to_string(nx_) + " coordinates - 3 x " +
                     std::to_string(numLinks()) + " links) needs " + std::to_string(m) + " input" +
                     (m == 1 ? "" : "s") + ", got " + std::to_string(numInputs()));
  }

  prescribed_.clear();
  for (Input& in : inputs_) {
    const Node& n = nodes_[in.node.value];
    switch (in.kind) {
      case InputKind::LinkAngle: {
        const Link& l = links_[in.link.value];
        in.coordinate = l.offset + (in.node == l.nodes[0] ? 0 : 1);
        break;
      }
      case InputKind::SliderPosition: in.coordinate = n.offset; break;
      case InputKind::NodeX: in.coordinate = n.offset; break;
      case InputKind::NodeY: in.coordinate = n.offset + 1; break;
    }
    prescribed_.push_back(in.coordinate);
  }
  unknown_.clear();
  for (int i = 0; i < nx_; ++i) {
    bool isInput = false;
    for (int p : prescribed_) isInput = isInput || p == i;
    if (!isInput) unknown_.push_back(i);
  }
  finalized_ = true;
}

VecX Linkage2d::initialCoordinates() const {
  requireFinalized("initialCoordinates()");
  VecX X = VecX::Zero(nx_);
  for (const Node& n : nodes_) {
    if (n.kind == NodeKind::Free) X.segment<2>(n.offset) = n.position;
    if (n.kind == NodeKind::Slider) X[n.offset] = 0.0;
  }
  for (const Link& l : links_) {
    const Vec2 d = nodes_[l.nodes[1].value].position - nodes_[l.nodes[0].value].position;
    const double beta = std::atan2(d.y(), d.x());
    X[l.offset] = beta;
    X[l.offset + 1] = beta;
  }
  return X;
}

VecX Linkage2d::inputRates() const {
  VecX r(numInputs());
  for (int i = 0; i < numInputs(); ++i) r[i] = inputs_[i].ratio;
  return r;
}

std::vector<std::string> Linkage2d::coordinateNames() const {
  requireFinalized("coordinateNames()");
  std::vector<std::string> names(nx_);
  for (const Node& n : nodes_) {
    if (n.kind == NodeKind::Free) {
      names[n.offset] = n.name + ".x";
      names[n.offset + 1] = n.name + ".y";
    } else if (n.kind == NodeKind::Slider) {
      names[n.offset] = n.name + ".s";
    }
  }
  for (const Link& l : links_) {
    names[l.offset] = l.name + ".beta1";
    names[l.offset + 1] = l.name + ".beta2";
  }
  return names;
}

Vec2 Linkage2d::nodePosition(NodeIndex i, const VecX& X) const {
  const Node& n = nodes_.at(i.value);
  switch (n.kind) {
    case NodeKind::Fixed: return n.position;
    case NodeKind::Free: return X.segment<2>(n.offset);
    case NodeKind::Slider: return n.position + X[n.offset] * n.direction;
  }
  return n.position;
}

Vec2 Linkage2d::nodeDerivative(NodeIndex i, const VecX& dX) const {
  const Node& n = nodes_.at(i.value);
  switch (n.kind) {
    case NodeKind::Fixed: return Vec2::Zero();
    case NodeKind::Free: return dX.segment<2>(n.offset);
    case NodeKind::Slider: return dX[n.offset] * n.direction;
  }
  return Vec2::Zero();
}

Mat2X Linkage2d::nodeMap(NodeIndex i) const {
  const Node& n = nodes_.at(i.value);
  switch (n.kind) {
    case NodeKind::Fixed: return Mat2X(2, 0);
    case NodeKind::Free: return Mat2::Identity();
    case NodeKind::Slider: return n.direction;
  }
  return Mat2X(2, 0);
}

LinkElement2d::Vec6 Linkage2d::elementCoordinates(LinkIndex i, const VecX& X) const {
  const Link& l = links_.at(i.value);
  LinkElement2d::Vec6 x;
  x.segment<2>(0) = nodePosition(l.nodes[0], X);
  x[2] = X[l.offset];
  x.segment<2>(3) = nodePosition(l.nodes[1], X);
  x[5] = X[l.offset + 1];
  return x;
}

VecX Linkage2d::deformations(const VecX& X) const {
  requireFinalized("deformations()");
  VecX eps(numDeformations());
  for (int k = 0; k < numLinks(); ++k) {
    eps.segment<3>(3 * k) = links_[k].element.deformations(elementCoordinates(LinkIndex(k), X));
  }
  return eps;
}

MatX Linkage2d::jacobian(const VecX& X) const {
  requireFinalized("jacobian()");
  MatX D = MatX::Zero(numDeformations(), nx_);
  for (int k = 0; k < numLinks(); ++k) {
    const Link& l = links_[k];
    const LinkElement2d::Mat36 De = l.element.jacobian(elementCoordinates(LinkIndex(k), X));
    // Chain rule through the node maps r = r(X): D_X = D_r dr/dX (free: I, slider: d).
    for (int end = 0; end < 2; ++end) {
      const Node& n = nodes_[l.nodes[end].value];
      const Mat2X map = nodeMap(l.nodes[end]);
      if (map.cols() > 0) D.block(3 * k, n.offset, 3, map.cols()) += De.block<3, 2>(0, 3 * end) * map;
      D.block<3, 1>(3 * k, l.offset + end) += De.col(3 * end + 2);
    }
  }
  return D;
}

VecX Linkage2d::secondDerivative(const VecX& X, const VecX& dX) const {
  requireFinalized("secondDerivative()");
  VecX out(numDeformations());
  // Node positions are affine in X, so the element's directional second derivative
  // along the mapped direction is the whole term.
  for (int k = 0; k < numLinks(); ++k) {
    const Link& l = links_[k];
    LinkElement2d::Vec6 dx;
    dx << nodeDerivative(l.nodes[0], dX), dX[l.offset], nodeDerivative(l.nodes[1], dX), dX[l.offset + 1];
    out.segment<3>(3 * k) = l.element.secondDerivative(elementCoordinates(LinkIndex(k), X), dx);
  }
  return out;
}

}  // namespace flexmbd
