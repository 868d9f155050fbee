#include "core/types.hpp"

#include <sstream>

#include "core/errors.hpp"

namespace flexmbd {

void requireFinite(double x, const std::string& what) {
  if (!std::isfinite(x)) {
    throw InputError(what + ": expected a finite number, got " + std::to_string(x));
  }
}

void requirePositive(double x, const std::string& what) {
  requireFinite(x, what);
  if (!(x > 0.0)) {
    std::ostringstream os;
    os << what << ": expected a positive number, got " << x;
    throw InputError(os.str());
  }
}

void requireNonNegative(double x, const std::string& what) {
  requireFinite(x, what);
  if (!(x >= 0.0)) {
    std::ostringstream os;
    os << what << " must be >= 0, got " << x;
    throw InputError(os.str());
  }
}

}  // namespace flexmbd
