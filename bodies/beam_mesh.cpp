#include "bodies/beam_mesh.hpp"

#include <string>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

/// n + 1 equally spaced nodes from `origin` along the body x axis, element i from node i
/// to node i + 1 made by `element(i)`.
template <class Mesh, class Point, class MakeElement>
Mesh straightMesh(double length, int numElements, const Point& origin, MakeElement element) {
  if (numElements < 1) throw InputError("beam mesh: elements must be >= 1, got " + std::to_string(numElements));
  requirePositive(length, "beam mesh: length");
  Mesh m;
  for (int i = 0; i <= numElements; ++i) m.nodes.push_back(origin + Point::UnitX() * (length * i / numElements));
  for (int i = 0; i < numElements; ++i) m.elements.push_back(element(i));
  return m;
}

}  // namespace

BeamMesh2d BeamMesh2d::straight(double length, int numElements, const BeamSection& section, const Vec2& origin) {
  return straightMesh<BeamMesh2d>(length, numElements, origin,
                                  [&](int i) { return BeamMesh2d::Element{i, i + 1, section}; });
}

BeamMesh3d BeamMesh3d::straight(double length, int numElements, const BeamSection3d& section, const Vec3& origin,
                                const Vec3& yHint) {
  return straightMesh<BeamMesh3d>(length, numElements, origin,
                                  [&](int i) { return BeamMesh3d::Element{i, i + 1, section, yHint}; });
}

}  // namespace flexmbd
