#include "dem/io/progress_line.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>

namespace grainflow {

namespace {

constexpr double redraw_interval_s = 0.5;
constexpr double line_interval_s = 30.0;
constexpr double line_progress_step = 0.1;

bool is_terminal(const std::ostream& out) {
  if (&out == &std::cout) return ::isatty(STDOUT_FILENO) == 1;
  if (&out == &std::cerr || &out == &std::clog) return ::isatty(STDERR_FILENO) == 1;
  return false;
}

double seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// h:mm:ss
std::string clock_text(double s) {
  if (!std::isfinite(s) || s < 0) return "-:--:--";
  const long total = std::lround(s);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
  return buf;
}

// Two significant digits in the compact form 1.2e5.
std::string rate_text(double r) {
  if (!std::isfinite(r) || r <= 0) return "-";
  int e = static_cast<int>(std::floor(std::log10(r)));
  double m = r / std::pow(10.0, e);
  if (m >= 9.95) {
    m /= 10.0;
    ++e;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1fe%d", m, e);
  return buf;
}

}  // namespace

ProgressLine::ProgressLine(MPI_Comm comm, double t_end, bool enabled, std::ostream& out,
                           Style style)
    : active_(enabled), t_end_(t_end), out_(out), constructed_(Clock::now()) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  active_ = enabled && rank == 0;
  redraw_ = style == Style::Redraw || (style == Style::Automatic && is_terminal(out));
}

ProgressLine::~ProgressLine() {
  if (active_ && line_open_) out_ << '\n' << std::flush;
}

std::string ProgressLine::status(Clock::time_point now) const {
  const double fraction = t_end_ > 0 ? t_ / t_end_ : 1.0;
  const double elapsed = seconds(now - first_update_);
  char buf[160];
  std::snprintf(buf, sizeof buf, "t = %.4g s / %g s (%.1f %%)  step %ld  %s particle-steps/s", t_,
                t_end_, 100.0 * fraction, step_,
                rate_text(elapsed > 0 ? particle_steps_ / elapsed : 0.0).c_str());
  return buf;
}

void ProgressLine::print(const std::string& line, bool final) {
  if (redraw_) {
    std::string padded = line;
    if (padded.size() < last_width_) padded.append(last_width_ - padded.size(), ' ');
    last_width_ = line.size();
    out_ << '\r' << padded;
    line_open_ = !final;
    if (final) out_ << '\n';
  } else {
    out_ << line << '\n';
  }
  out_ << std::flush;
}

void ProgressLine::update(double t, long step, long particles) {
  if (!active_ || finished_) return;
  const Clock::time_point now = Clock::now();
  const bool first = !started_;
  if (first) {
    started_ = true;
    first_update_ = now;
    t_first_ = t;
  } else {
    particle_steps_ += static_cast<double>(particles) * static_cast<double>(step - step_);
  }
  t_ = t;
  step_ = step;

  const double fraction = t_end_ > 0 ? t / t_end_ : 1.0;
  const double since_print = seconds(now - last_print_);
  bool due;
  if (redraw_) {
    due = first || since_print >= redraw_interval_s;
  } else {
    // The tolerance keeps 0.15 / 0.5 = 0.29999999999999999 from missing the 30 % mark.
    due = first || fraction >= next_mark_ - 1e-9 || since_print >= line_interval_s;
  }
  if (!due) return;
  if (!redraw_)
    next_mark_ = (std::floor(fraction / line_progress_step + 1e-9) + 1.0) * line_progress_step;
  last_print_ = now;

  const double elapsed = seconds(now - first_update_);
  const double eta = t > t_first_ ? elapsed * (t_end_ - t) / (t - t_first_) : -1.0;
  print(status(now) + "  ETA " + clock_text(eta), false);
}

void ProgressLine::finish() {
  if (!active_ || finished_) return;
  finished_ = true;
  const Clock::time_point now = Clock::now();
  const std::string wall = "wall " + clock_text(seconds(now - constructed_));
  print(started_ ? status(now) + "  " + wall : "no steps taken  " + wall, true);
}

}  // namespace grainflow
