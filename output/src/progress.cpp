#include "spinesim/output/progress.hpp"

#include "spinesim/output/format.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

namespace spinesim::output {

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

Progress::Progress(int stages, bool quiet)
    : stages_(stages), quiet_(quiet || !stderr_is_terminal()) {}

void Progress::begin(const std::string& what) {
  ++current_;
  timer_.restart();
  if (!quiet_)
    std::cerr << "[" << current_ << (stages_ > 0 ? "/" + std::to_string(stages_) : "") << "] "
              << what << " ..." << std::flush;
}

double Progress::end(const std::string& detail) {
  const double s = timer_.seconds();
  if (!quiet_)
    std::cerr << " done, " << fixed(s, 2) << " s" << (detail.empty() ? "" : " (" + detail + ")")
              << std::endl;
  return s;
}

StageHooks Progress::hooks() {
  StageHooks h;
  h.begin = [this](const std::string& what) { begin(what); };
  h.end = [this](const std::string& detail) { end(detail); };
  return h;
}

std::string human_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 10) return fixed(s, 1) + " s";
  const long total = std::lround(s);
  if (total < 60) return std::to_string(total) + " s";
  if (total < 3600) return std::to_string(total / 60) + " min " + std::to_string(total % 60) + " s";
  const long min = (total % 3600) / 60;
  return std::to_string(total / 3600) + " h " + (min < 10 ? "0" : "") + std::to_string(min) +
         " min";
}

ProgressBar::ProgressBar(int total, bool quiet, std::string unit)
    : total_(std::max(total, 0)), quiet_(quiet || !stderr_is_terminal()), unit_(std::move(unit)) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::finish() {
  if (drawn_) std::cerr << "\r\033[K" << std::flush;
  drawn_ = false;
}

std::string ProgressBar::render(int done, int total, double elapsed_s, const std::string& label,
                                const std::string& unit, int width) {
  done = std::clamp(done, 0, std::max(total, 0));
  const double fraction = total > 0 ? double(done) / total : 1.0;
  const int filled = int(std::floor(fraction * width));
  std::ostringstream os;
  if (!label.empty()) os << label << "  ";
  os << "[" << std::string(std::size_t(filled), '#')
     << std::string(std::size_t(width - filled), '.') << "]  " << done << "/" << total
     << (unit.empty() ? "" : " " + unit) << "  " << std::lround(100 * fraction) << " %";
  if (done > 0 && done < total) os << "  ETA " << human_duration(elapsed_s / done * (total - done));
  return os.str();
}

void ProgressBar::update(int done, const std::string& label) {
  if (quiet_) return;
  const double now = timer_.seconds();
  if (done < total_ && last_draw_s_ >= 0 && now - last_draw_s_ < 0.1) return;
  last_draw_s_ = now;
  std::cerr << "\r\033[K  " << render(done, total_, now, label, unit_) << std::flush;
  drawn_ = true;
}

std::function<void(int, int)> ProgressBar::callback() {
  if (quiet_) return {};
  return [this](int done, int total) {
    total_ = total;
    update(done);
  };
}

}  // namespace spinesim::output
