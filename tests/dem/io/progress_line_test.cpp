// ProgressLine: format of the line, throttling to one line per 10 % of progress when not on a
// terminal, in-place redraw on a terminal, silence when disabled. Reference: the format stated
// in progress_line.hpp; the 10 % rule gives exactly 11 lines for progress 0..100 % in 1 % steps
// (a fast test never reaches the 30 s wall-clock rule).
#include "dem/io/progress_line.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace grainflow {
namespace {


std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

TEST(ProgressLine, PipeGetsOneLinePerTenPercent) {
  std::ostringstream out;
  {
    ProgressLine progress(MPI_COMM_WORLD, 0.5, true, out, ProgressLine::Style::Lines);
    for (int i = 0; i <= 100; ++i) progress.update(0.005 * i, 10L * i, 1000);
    progress.finish();
  }
  const std::vector<std::string> lines = lines_of(out.str());
  ASSERT_EQ(lines.size(), 12u) << out.str();  // 0 %, 10 %, ..., 100 %, then the final line
  EXPECT_EQ(out.str().find('\r'), std::string::npos);
  const std::regex running(
      R"(t = [0-9.e+-]+ s / 0\.5 s \( *[0-9]+\.[0-9] %\)  step [0-9]+  ([0-9]\.[0-9]e-?[0-9]+|-) particle-steps/s  ETA ([0-9]+:[0-9]{2}:[0-9]{2}|-:--:--))");
  for (std::size_t i = 0; i + 1 < lines.size(); ++i)
    EXPECT_TRUE(std::regex_match(lines[i], running)) << lines[i];
  EXPECT_EQ(lines[0].rfind("t = 0 s / 0.5 s (0.0 %)  step 0  ", 0), 0u) << lines[0];
  EXPECT_EQ(lines[5].rfind("t = 0.25 s / 0.5 s (50.0 %)  step 500  ", 0), 0u) << lines[5];
  const std::regex final_line(
      R"(t = 0\.5 s / 0\.5 s \(100\.0 %\)  step 1000  ([0-9]\.[0-9]e-?[0-9]+|-) particle-steps/s  wall [0-9]+:[0-9]{2}:[0-9]{2})");
  EXPECT_TRUE(std::regex_match(lines.back(), final_line)) << lines.back();
}

TEST(ProgressLine, TerminalRedrawsInPlaceAndEndsWithNewline) {
  std::ostringstream out;
  ProgressLine progress(MPI_COMM_WORLD, 1.0, true, out, ProgressLine::Style::Redraw);
  progress.update(0.0, 0, 10);
  progress.update(0.5, 5, 10);  // within 0.5 s of the first draw: not redrawn
  progress.finish();
  const std::string s = out.str();
  EXPECT_EQ(s.front(), '\r');
  EXPECT_EQ(s.back(), '\n');
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 1);
  EXPECT_EQ(std::count(s.begin(), s.end(), '\r'), 2);  // first draw and final line
  EXPECT_NE(s.find("(50.0 %)  step 5"), std::string::npos) << s;
}

TEST(ProgressLine, DisabledPrintsNothing) {
  std::ostringstream out;
  ProgressLine progress(MPI_COMM_WORLD, 1.0, false, out, ProgressLine::Style::Lines);
  progress.update(0.5, 5, 10);
  progress.finish();
  EXPECT_TRUE(out.str().empty());
}

TEST(ProgressLine, StringStreamIsNotATerminal) {
  std::ostringstream out;
  ProgressLine progress(MPI_COMM_WORLD, 1.0, true, out);
  progress.update(0.0, 0, 10);
  EXPECT_EQ(out.str().find('\r'), std::string::npos);
}

TEST(ProgressLine, AbortedRedrawGetsItsNewline) {
  std::ostringstream out;
  {
    ProgressLine progress(MPI_COMM_WORLD, 1.0, true, out, ProgressLine::Style::Redraw);
    progress.update(0.1, 1, 10);
  }  // destroyed without finish(), as when an exception unwinds the run
  EXPECT_EQ(out.str().back(), '\n');
}

}  // namespace
}  // namespace grainflow
