#include "elements/beam_section.hpp"

#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/types.hpp"

namespace flexmbd {

void BeamSection::validate(const std::string& owner) const {
  requirePositive(area, owner + ": section area");
  requirePositive(inertia, owner + ": section inertia (second moment of area)");
  requirePositive(youngsModulus, owner + ": section youngs_modulus");
  requirePositive(density, owner + ": section density");
  requireFinite(damping, owner + ": section damping");
  if (damping < 0.0) {
    std::ostringstream os;
    os << owner << ": section damping must be >= 0, got " << damping;
    throw InputError(os.str());
  }
}

BeamSection rectangularSection(double width, double height, double youngsModulus, double density,
                               double damping) {
  BeamSection s;
  s.area = width * height;
  s.inertia = width * height * height * height / 12.0;
  s.youngsModulus = youngsModulus;
  s.density = density;
  s.damping = damping;
  return s;
}

}  // namespace flexmbd
