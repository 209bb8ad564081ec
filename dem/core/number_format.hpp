#pragma once
// Numbers in user-facing messages. A reported quantity gets significant digits, never a
// fixed count of decimals (std::to_string prints 1e-9 m^3 as "0.000000"); a value that is
// compared with a limit gets every digit it needs to differ from that limit.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// x rounded down to three significant digits, as the double nearest that decimal (a proposed
// step that, printed, is below the limit it stays under: 1.0599e-4 -> 1.05e-4).
inline double round_down_3(double x) {
  if (!(x > 0) || !std::isfinite(x)) return x;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", x);  // nearest: d.dd e+-XX
  double y = std::strtod(buf, nullptr);
  if (y > x) {  // one unit down in the third digit
    int exponent = std::atoi(buf + 5);
    int digits = (buf[0] - '0') * 100 + (buf[2] - '0') * 10 + (buf[3] - '0') - 1;
    if (digits < 100) {  // 1.00e-2 above x: 9.99e-3
      digits = 999;
      --exponent;
    }
    std::snprintf(buf, sizeof buf, "%de%d", digits, exponent - 2);
    y = std::strtod(buf, nullptr);
  }
  return y;
}

// x rounded up to three significant digits, as the double nearest that decimal (so that it
// prints as three digits and reads back as itself): a proposed length that is above the bound
// it must reach (2.4000000000000002e-3 -> 2.41e-3).
inline double round_up_3(double x) {
  if (!(x > 0) || !std::isfinite(x)) return x;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", x);  // nearest: d.dd e+-XX
  double y = std::strtod(buf, nullptr);
  if (y < x) {  // one unit up in the third digit
    const int exponent = std::atoi(buf + 5);
    const int digits = (buf[0] - '0') * 100 + (buf[2] - '0') * 10 + (buf[3] - '0') + 1;
    std::snprintf(buf, sizeof buf, "%de%d", digits, exponent - 2);
    y = std::strtod(buf, nullptr);
  }
  return y;
}

}  // namespace grainflow
