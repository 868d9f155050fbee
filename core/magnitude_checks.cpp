#include "core/magnitude_checks.hpp"

#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {

void checkMagnitudeSpread(const std::string& kind, const std::vector<NamedMagnitude>& values) {
  const NamedMagnitude* smallest = nullptr;
  const NamedMagnitude* largest = nullptr;
  for (const NamedMagnitude& v : values) {
    if (!(v.value > 0.0)) continue;
    if (!smallest || v.value < smallest->value) smallest = &v;
    if (!largest || v.value > largest->value) largest = &v;
  }
  if (!smallest || largest->value <= kMaxMagnitudeRatio * smallest->value) return;
  throw InputError(smallest->owner + ": " + kind + " " + fmt(smallest->value) + " is " +
                   fmt(largest->value / smallest->value, 3) + " times smaller than the " + kind + " " +
                   fmt(largest->value) + " of " + largest->owner + " (expected values of one kind within a ratio of " +
                   fmt(kMaxMagnitudeRatio) + ": beyond it the smaller one's motion is lost in the round-off of "
                   "the larger one's terms)");
}

std::string vectorText(const Eigen::Ref<const VecX>& v) {
  std::string out = "[";
  for (Eigen::Index k = 0; k < v.size(); ++k) out += (k > 0 ? ", " : "") + fmt(v[k]);
  return out + "]";
}

std::string directionProblem(const Eigen::Ref<const VecX>& v) {
  if (!v.allFinite() || (v.array() == 0.0).all()) return "must be a finite non-zero vector, got " + vectorText(v);
  const double largest = v.cwiseAbs().maxCoeff();
  const double length = largest * (v / largest).norm();  // scaled: 1e-300 for [1e-300, 0, 0], no underflow
  if (length < kMinPositiveMagnitude) {
    return "is too small to normalise, got " + vectorText(v) + " (length " + fmt(length) +
           "; expected a direction of length at least " + fmt(kMinPositiveMagnitude) + ")";
  }
  return "";
}

template <class Vec>
Vec unitDirection(const Vec& v, const std::string& who) {
  const std::string problem = directionProblem(v);
  if (!problem.empty()) throw InputError(who + " " + problem);
  return v.normalized();
}

template Vec2 unitDirection<Vec2>(const Vec2&, const std::string&);
template Vec3 unitDirection<Vec3>(const Vec3&, const std::string&);

}  // namespace flexmbd
