#include "bodies/body_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "bodies/fe_body_data.hpp"

#include "core/errors.hpp"

namespace flexmbd {
namespace {

/// The shape's own axes with its axis along z: for an axis k, (x, y, z) of the facets
/// becomes a permutation putting z on axis k (right-handed: cyclic).
Vec3 alongAxis(const Vec3& p, int axis) {
  switch (axis) {
    case 0: return Vec3(p.z(), p.x(), p.y());
    case 1: return Vec3(p.y(), p.z(), p.x());
    default: return p;
  }
}

void box(const Vec3& size, SurfaceMesh& m) {
  const Vec3 h = 0.5 * size;
  for (int k = 0; k < 8; ++k) m.points.emplace_back(k & 1 ? h.x() : -h.x(), k & 2 ? h.y() : -h.y(), k & 4 ? h.z() : -h.z());
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
}

/// Rings of radius r at z = -h/2 and +h/2 (2n points from `first`); the side facets face
/// outward (outward = true) or inward (a tube's bore).
void ringSide(double r, double h, int n, bool outward, SurfaceMesh& m, int& first) {
  first = static_cast<int>(m.points.size());
  for (int end = 0; end < 2; ++end) {
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * M_PI * k / n;
      m.points.emplace_back(r * std::cos(a), r * std::sin(a), end == 0 ? -0.5 * h : 0.5 * h);
    }
  }
  for (int k = 0; k < n; ++k) {
    const int a = first + k, b = first + (k + 1) % n, c = b + n, d = a + n;
    m.faces.push_back(outward ? std::vector<int>{a, b, c, d} : std::vector<int>{a, d, c, b});
  }
}

void cylinderOrTube(const SolidShape& s, int n, SurfaceMesh& m) {
  int outer = 0;
  ringSide(s.radius, s.length, n, true, m, outer);
  if (s.type == SolidShape::Type::Cylinder || s.innerRadius == 0.0) {
    std::vector<int> bottom, top;
    for (int k = 0; k < n; ++k) {
      bottom.push_back(outer + n - 1 - k);  // seen from -z: clockwise in +z view
      top.push_back(outer + n + k);
    }
    m.faces.push_back(bottom);
    m.faces.push_back(top);
    return;
  }
  int inner = 0;
  ringSide(s.innerRadius, s.length, n, false, m, inner);
  for (int k = 0; k < n; ++k) {  // the annular end faces
    const int k1 = (k + 1) % n;
    m.faces.push_back({outer + k, inner + k, inner + k1, outer + k1});
    m.faces.push_back({outer + n + k, outer + n + k1, inner + n + k1, inner + n + k});
  }
}

void sphere(double r, int n, SurfaceMesh& m) {
  const int bands = std::max(2, n / 2);
  m.points.emplace_back(0.0, 0.0, -r);  // south pole
  for (int i = 1; i < bands; ++i) {
    const double polar = M_PI * i / bands;
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * M_PI * k / n;
      m.points.emplace_back(r * std::sin(polar) * std::cos(a), r * std::sin(polar) * std::sin(a), -r * std::cos(polar));
    }
  }
  m.points.emplace_back(0.0, 0.0, r);  // north pole
  const int north = static_cast<int>(m.points.size()) - 1;
  const auto ring = [n](int i, int k) { return 1 + (i - 1) * n + (k % n); };
  for (int k = 0; k < n; ++k) m.faces.push_back({0, ring(1, k + 1), ring(1, k)});
  for (int i = 1; i + 1 < bands; ++i) {
    for (int k = 0; k < n; ++k) m.faces.push_back({ring(i, k), ring(i, k + 1), ring(i + 1, k + 1), ring(i + 1, k)});
  }
  for (int k = 0; k < n; ++k) m.faces.push_back({north, ring(bands - 1, k), ring(bands - 1, k + 1)});
}

}  // namespace

SurfaceMesh surfaceMesh(const SolidShape& s, int segments) {
  shapeVolume(s);  // the dimensions' checks
  if (segments < 3) throw InputError("surfaceMesh: segments must be >= 3, got " + std::to_string(segments));
  SurfaceMesh m;
  switch (s.type) {
    case SolidShape::Type::Box: box(s.size, m); break;
    case SolidShape::Type::Cylinder:
    case SolidShape::Type::Tube: cylinderOrTube(s, segments, m); break;
    case SolidShape::Type::Sphere: sphere(s.radius, segments, m); break;
  }
  const bool axial = s.type == SolidShape::Type::Cylinder || s.type == SolidShape::Type::Tube;
  for (Vec3& p : m.points) p = s.offset + s.orientation * (axial ? alongAxis(p, s.axis) : p);
  return m;
}

namespace {

/// The faces of a solid element as its corner nodes (0-based positions in its node list),
/// counter-clockwise seen from outside for the codes' node order; a shell (Abaqus S3, S3R,
/// S4, S4R, S8R) is its own face; empty for other types (beams, point elements).
const std::vector<std::vector<int>>& elementFaces(const std::string& type) {
  static const std::vector<std::vector<int>> hex = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                    {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  static const std::vector<std::vector<int>> tet = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  static const std::vector<std::vector<int>> wedge = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
  static const std::vector<std::vector<int>> pyramid = {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  static const std::vector<std::vector<int>> shell3 = {{0, 1, 2}}, shell4 = {{0, 1, 2, 3}};
  static const std::vector<std::vector<int>> none;
  const auto starts = [&](const char* p) { return type.rfind(p, 0) == 0; };
  if (starts("C3D8") || starts("C3D20") || starts("Hex")) return hex;
  if (starts("C3D4") || starts("C3D10") || starts("Tet")) return tet;
  if (starts("C3D6") || starts("C3D15") || starts("Wedge")) return wedge;
  if (starts("Pyramid")) return pyramid;
  if (starts("S3")) return shell3;
  if (starts("S4") || starts("S8")) return shell4;
  return none;
}

}  // namespace

SurfaceMesh outerSurface(const FeBodyData& d) {
  SurfaceMesh m;
  m.points = d.coordinates;
  // a face shared by two elements is inside: count each face by its sorted nodes
  std::map<std::vector<int>, std::pair<int, std::vector<int>>> faces;  // key -> (count, oriented face)
  for (const FeElement& e : d.elements) {
    for (const std::vector<int>& f : elementFaces(e.type)) {
      std::vector<int> face;
      for (int k : f) {
        if (k < static_cast<int>(e.nodes.size())) face.push_back(e.nodes[k]);
      }
      if (face.size() != f.size()) continue;  // fewer nodes than the type has corners
      std::vector<int> key = face;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      if (entry.first++ == 0) entry.second = face;
    }
  }
  for (const auto& [key, entry] : faces) {
    if (entry.first == 1) m.faces.push_back(entry.second);
  }
  return m;
}

}  // namespace flexmbd
