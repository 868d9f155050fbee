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

}  // namespace flexmbd
