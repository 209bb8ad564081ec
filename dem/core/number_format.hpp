#pragma once
// Numbers in user-facing messages. A reported quantity gets significant digits, never a
// fixed count of decimals (std::to_string prints 1e-9 m^3 as "0.000000"); a value that is
// compared with a limit gets every digit it needs to differ from that limit.
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>

namespace grainflow {

// The shortest decimal that reads back as the same double (0.009000000000000001, 0.01).
inline std::string exact_number(double x) {
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
  return std::string(buf, end);
}

// x with `digits` significant digits (1.234e-09, 0.5, 1500).
inline std::string significant(double x, int digits = 4) {
  std::ostringstream o;
  o.precision(digits);
  o << x;
  return o.str();
}

// x rounded down to three significant digits (a proposed step that, printed, is below the
// limit it stays under: 1.0599e-4 -> 1.05e-4).
inline double round_down_3(double x) {
  if (!(x > 0) || !std::isfinite(x)) return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 2);
  double y = std::floor(x / scale) * scale;
  while (y > x) y = std::nextafter(y, 0.0);
  return y;
}

}  // namespace grainflow
