// Numbers proposed in messages (dem/core/number_format.hpp) must work when set as written: a
// step rounded down stays under its limit, a length rounded up reaches its bound, and both
// print as three digits that read back as the same double. Reference: the bounds themselves
// (x <= limit, x >= bound) over a sweep of magnitudes and mantissas, including the values
// whose decimal scale is inexact in binary (2 r + 0.4 r = 0.0024000000000000002 for
// r = 0.5 mm printed as 0.0024 and was then refused again: the advice_reruns test).
#include "dem/core/number_format.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace grainflow {
namespace {

// The number of significant digits of the shortest text of x.
int digits_of(double x) {
  std::string s = exact_number(x);
  const auto e = s.find('e');
  if (e != std::string::npos) s = s.substr(0, e);
  int n = 0;
  bool leading = true;
  for (char c : s) {
    if (c < '0' || c > '9') continue;
    if (leading && c == '0') continue;
    leading = false;
    ++n;
  }
  // Trailing zeros of a whole number (124000) are not significant.
  while (n > 0 && s.find('.') == std::string::npos && s.back() == '0') {
    s.pop_back();
    --n;
  }
  return n;
}

TEST(NumberFormat, RoundUp3ReachesTheBoundInThreeDigits) {
  EXPECT_EQ(exact_number(round_up_3(2 * (2 * 5e-4 + 0.4 * 5e-4))), "0.00241");
  EXPECT_EQ(exact_number(round_up_3(0.0024)), "0.0024");
  EXPECT_EQ(exact_number(round_up_3(0.00123456)), "0.00124");
  EXPECT_EQ(exact_number(round_up_3(0.0099999)), "0.01");
  int checked = 0;
  for (int e = -12; e <= 12; ++e)
    for (int k = 0; k < 997; ++k) {
      const double x = (1 + k * 0.009037) * std::pow(10.0, e);
      const double y = round_up_3(x);
      ASSERT_GE(y, x) << exact_number(x);
      ASSERT_LE(y, x * 1.0101) << exact_number(x);  // at most one unit of the third digit
      ASSERT_LE(digits_of(y), 3) << exact_number(x) << " -> " << exact_number(y);
      ASSERT_EQ(std::strtod(exact_number(y).c_str(), nullptr), y);
      ++checked;
    }
  EXPECT_EQ(checked, 25 * 997);
}

TEST(NumberFormat, RoundDown3StaysUnderTheLimit) {
  EXPECT_EQ(exact_number(round_down_3(1e-11)), "1e-11");  // was 9.9e-12: log10 and pow rounding
  EXPECT_EQ(exact_number(round_down_3(1.0599e-4)), "0.000105");
  EXPECT_EQ(exact_number(round_down_3(0.0099999)), "0.00999");
  for (int e = -12; e <= 12; ++e)
    for (int k = 0; k < 997; ++k) {
      const double x = (1 + k * 0.009037) * std::pow(10.0, e);
      const double y = round_down_3(x);
      ASSERT_LE(y, x) << exact_number(x);
      ASSERT_GE(y, x / 1.0101) << exact_number(x);
      ASSERT_LE(digits_of(y), 3) << exact_number(x) << " -> " << exact_number(y);
    }
}

}  // namespace
}  // namespace grainflow
