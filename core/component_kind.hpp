/// @file
/// The declaration of a kind of component (a joint, and in time every body, driver,
/// force and output): its scene name, its keys with their types, units
/// and one-line descriptions, and how it is built from their values. One declaration
/// serves every front end: the scene readers validate an object against it and build it
/// (scene/component_reader.hpp), the key reference of docs/scene-format.md is generated
/// from it, and the Python module makes one `add_<type>_<kind>` method of each.
/// The kinds are listed, one line each, in builders/component_kinds.cpp.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "core/system.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// What a key holds (its value's JSON shape and how it is checked).
enum class KeyType {
  BodyPair,   ///< two body names, ["ground", "slider"] ("ground": the ground)
  PointPair,  ///< two points, each in its body's axes: 2 coordinates each in a planar scene, 3 in a spatial one
  Direction,  ///< a direction (2 or 3 coordinates as the scene; normalised, not zero)
};

/// Scenes a kind may appear in.
enum class KindDimensions { Planar, Spatial, Both };

/// One key of a kind ("name" and "type", which every kind has, are not listed). Every
/// key is required: numbers, ranges and defaults join the vocabulary with the first kind
/// that needs them.
struct KeySpec {
  std::string name;
  KeyType type;
  std::string unit;         ///< SI unit of the value ("m", "rad", ""); a direction or point's coordinates
  std::string description;  ///< one sentence
};

/// The values of one object's keys, read by a front end that has checked them against
/// the kind's KeySpecs (present and of their type). Points and directions are spatial;
/// in a planar scene their z is 0.
class ComponentArgs {
 public:
  virtual ~ComponentArgs() = default;
  /// 2 (planar scene) or 3 (spatial).
  virtual int dimension() const = 0;
  /// The object's "name".
  virtual const std::string& name() const = 0;
  virtual std::array<BodyIndex, 2> bodyPair(const std::string& key) const = 0;
  virtual std::array<Vec3, 2> pointPair(const std::string& key) const = 0;
  /// A unit vector.
  virtual Vec3 direction(const std::string& key) const = 0;
};

/// A kind of component.
struct ComponentKind {
  std::string section;  ///< the scene's array it belongs to: "joints"
  std::string type;     ///< its "type" in a scene
  KindDimensions dimensions = KindDimensions::Both;
  std::string summary;  ///< one sentence for the reference
  std::vector<KeySpec> keys;
  /// Builds the component into the (not yet finalized) system from validated values.
  std::function<void(System&, const ComponentArgs&)> build;

  bool allows(int dimension) const {
    return dimensions == KindDimensions::Both || (dimension == 2) == (dimensions == KindDimensions::Planar);
  }
};

}  // namespace flexmbd
