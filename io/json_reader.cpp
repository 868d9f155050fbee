#include "io/json_reader.hpp"

#include "io/scene_keys.hpp"

namespace flexmbd::jsonread {

TimeLawPtr parseTimeLaw(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  const std::string type =
      readType(r, "law", {"constant", "constant_speed", "polynomial", "harmonic", "spin_up", "tabulated"});
  const std::string forA = " for a " + type + " law";
  if (type == "constant") {
    r.allowOnly(scenekeys::kLawConstant, forA);
    const double value = r.number("value");
    return located(where, [&] { return makeConstantLaw(value); });
  }
  if (type == "constant_speed") {
    r.allowOnly(scenekeys::kLawConstantSpeed, forA);
    const double speed = r.number("speed");
    const double initial = r.number("initial", 0.0);
    return located(where, [&] { return makeConstantSpeedLaw(speed, initial); });
  }
  if (type == "polynomial") {
    r.allowOnly(scenekeys::kLawPolynomial, forA);
    std::vector<double> c = r.numbers("coefficients");
    return located(where, [&] { return makePolynomialLaw(std::move(c)); });
  }
  if (type == "harmonic") {
    r.allowOnly(scenekeys::kLawHarmonic, forA);
    const double amplitude = r.number("amplitude");
    const double omega = r.number("omega");
    const double phase = r.number("phase", 0.0);
    const double offset = r.number("offset", 0.0);
    return located(where, [&] { return makeHarmonicLaw(amplitude, omega, phase, offset); });
  }
  if (type == "spin_up") {
    r.allowOnly(scenekeys::kLawSpinUp, forA);
    const double speed = r.number("speed");
    const double rampTime = r.positive("ramp_time");
    const double initial = r.number("initial", 0.0);
    return located(where, [&] { return makeSpinUpLaw(speed, rampTime, initial); });
  }
  // tabulated
  r.allowOnly(scenekeys::kLawTabulated, forA);
  std::vector<double> times = r.numbers("times");
  std::vector<double> values = r.numbers("values");
  if (times.size() != values.size()) {
    r.fail("keys \"times\" and \"values\" must have the same length, got " + std::to_string(times.size()) +
           " and " + std::to_string(values.size()));
  }
  return located(where, [&] { return makeTabulatedLaw(std::move(times), std::move(values)); });
}

}  // namespace flexmbd::jsonread
