/// @file
/// Input values that are positive but numerically meaningless next to the rest of the
/// model: one bound for the smallest magnitude of any positive scene value
/// and one for the spread of the values of one kind (masses, inertias, stiffnesses, lengths);
/// the same smallest magnitude for the length of an axis or direction .
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"

namespace flexmbd {

/// Smallest positive magnitude of a physical value: the inverse of the largest one read
/// (1e100, scene/json_reader.hpp), so that products and quotients of three values stay
/// normal doubles (1e-300 to 1e300); a subnormal mass (5e-324) gives 1/m = inf.
constexpr double kMinPositiveMagnitude = 1e-100;

/// Widest ratio of two values of one kind in one model. The light body's equations carry
/// round-off of eps times the heavy one's terms (eps = 2.2e-16): at 1e12 that is 2.2e-4
/// of its own, within a factor 50 of the coarsest rtol accepted (1e-2); a wider spread
/// leaves the light part's motion as round-off at every tolerance the solver accepts.
constexpr double kMaxMagnitudeRatio = 1e12;

struct NamedMagnitude {
  std::string owner;  ///< e.g. "body 'slider'", "node 'm2'"
  double value;       ///< positive; zeros are skipped (massless nodes)
};

/// Refuses (InputError) a set of values of one kind (`kind`, e.g. "mass") whose largest is
/// more than kMaxMagnitudeRatio times its smallest, naming both owners, values and the ratio.
void checkMagnitudeSpread(const std::string& kind, const std::vector<NamedMagnitude>& values);

/// "" if `v` can be normalised to a direction (an axis): finite, of length at least
/// kMinPositiveMagnitude (below it, the squared length the normalisation divides by is
/// subnormal or 0 and the "unit" vector is not of length 1); otherwise what is wrong, to
/// follow the vector's name: "must be a finite non-zero vector, got [0, 0, 0]", "is too
/// small to normalise, got [1e-300, 0, 0] (length 1e-300; expected a direction of length
/// at least 1e-100)". The one rule for every axis and direction of every model and reader.
std::string directionProblem(const Eigen::Ref<const VecX>& v);

/// `v` / |v| for a 2- or 3-vector `v`.
/// @throws InputError "<who> <directionProblem(v)>" if it cannot be normalised.
template <class Vec>
Vec unitDirection(const Vec& v, const std::string& who);

/// "[1e-300, 0, 0]": a vector in a message, each entry as fmt() prints it.
std::string vectorText(const Eigen::Ref<const VecX>& v);

}  // namespace flexmbd
