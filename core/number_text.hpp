/// @file
/// Numbers in messages: the shortest text that reads back as the same double, in plain
/// decimal notation for magnitudes from 1e-4 to 1e6 ("-80", "0.001", "123456.5") and in
/// exponent notation outside ("1e-08", "2.5e+20"). "%.1g" alone would print -80 as
/// "-8e+01" (it reads back exactly, but no reader expects it). fmt() is the one number
/// formatter of the engine's messages: shortest by default, or a fixed number
/// of significant digits.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace flexmbd {

inline std::string shortestNumberText(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  const double a = std::fabs(x);
  const bool plain = a == 0.0 || (a >= 1e-4 && a < 1e6);  // %g writes plain decimals for p > exponent
  char buf[40];
  for (int p = 1; p <= 17; ++p) {
    std::snprintf(buf, sizeof buf, "%.*g", p, x);
    if (std::strtod(buf, nullptr) != x) continue;
    if (plain && std::strchr(buf, 'e') != nullptr) continue;
    break;
  }
  return buf;
}

/// A number in a message: shortestNumberText(x) by default; with digits > 0, printf's
/// "%.<digits>g" (6: a stream's default precision, as the command line prints times and
/// CPU seconds; 10: the input angles of the kinematic analysis).
inline std::string fmt(double x, int digits = 0) {
  if (digits <= 0) return shortestNumberText(x);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

}  // namespace flexmbd
