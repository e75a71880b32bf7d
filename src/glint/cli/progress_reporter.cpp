#include "glint/cli/progress_reporter.h"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "glint/cli/console.h"

namespace glint::cli {
namespace {

constexpr auto kBarInterval = std::chrono::milliseconds(100);  // terminal redraw rate limit
constexpr auto kLineInterval = std::chrono::seconds(2);        // log line rate when no 10% step
constexpr int kBarCells = 30;

int percentOf(std::size_t done, std::size_t total) {
  return total == 0 ? 100 : static_cast<int>(done * 100 / total);
}

// Remaining time, extrapolated linearly from the tiles rendered so far (tiles `resumed` from a
// checkpoint took no time); negative when unknown.
double etaSeconds(std::size_t done, std::size_t total, std::size_t resumed, double elapsed) {
  if (done <= resumed || total == 0) return -1;
  return elapsed * static_cast<double>(total - done) / static_cast<double>(done - resumed);
}

std::string formatEta(double eta) { return eta < 0 ? std::string("--") : formatDuration(eta); }

}  // namespace

std::string formatDuration(double seconds) {
  if (!(seconds >= 0)) seconds = 0;
  if (seconds < 9.995) return fmt::format("{:.2f} s", seconds);
  if (seconds < 59.95) return fmt::format("{:.1f} s", seconds);
  const auto whole = static_cast<long long>(std::llround(seconds));
  if (whole < 3600) return fmt::format("{} min {:02} s", whole / 60, whole % 60);
  return fmt::format("{} h {:02} min", whole / 3600, (whole % 3600) / 60);
}

ProgressReporter::Style ProgressReporter::styleFor(std::FILE* stream) {
  return isatty(fileno(stream)) ? Style::Bar : Style::Lines;
}

ProgressReporter::ProgressReporter(Style style, std::FILE* stream)
    : style_(style), stream_(stream), start_(Clock::now()), lastDraw_(start_) {}

void ProgressReporter::start(std::size_t resumed) {
  resumed_ = resumed;
  start_ = lastDraw_ = Clock::now();
  lastDecile_ = 0;
  if (style_ == Style::Bar) drawBar(0, 1, 0);
}

double ProgressReporter::elapsedSeconds() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

void ProgressReporter::update(std::size_t done, std::size_t total) {
  if (style_ == Style::Silent) return;
  const auto now = Clock::now();
  const double elapsed = elapsedSeconds();
  if (style_ == Style::Bar) {
    if (done == total || now - lastDraw_ >= kBarInterval) {
      drawBar(done, total, elapsed);
      lastDraw_ = now;
    }
    return;
  }
  const int decile = percentOf(done, total) / 10;
  if (decile > lastDecile_ || now - lastDraw_ >= kLineInterval) {
    if (lastPrinted100_) return;  // never repeat the final line
    printLine(done, total, elapsed);
    lastDecile_ = std::max(decile, lastDecile_);
    lastDraw_ = now;
    lastPrinted100_ = done == total;
  }
}

void ProgressReporter::finish() {
  if (style_ == Style::Bar && barDrawn_) {
    emit(stream_, "\n");
    barDrawn_ = false;
    barLength_ = 0;
  }
}

void ProgressReporter::drawBar(std::size_t done, std::size_t total, double elapsed) {
  const int percent = percentOf(done, total);
  const std::string times =
      fmt::format("{:3}%  elapsed {}  ETA {}", percent, formatDuration(elapsed),
                  formatEta(etaSeconds(done, total, resumed_, elapsed)));
  // The line must stay shorter than the terminal: a line that wraps makes every redraw ('\r'
  // returns only to the start of the last row) a new row. The bar gives up cells first, then the
  // line is cut.
  const std::size_t columns = terminalColumns();
  const std::size_t frame = std::string_view("glint: [] ").size() + times.size();
  int cells = kBarCells;
  if (columns != 0 && frame + kBarCells >= columns) {
    cells = frame + 1 < columns ? static_cast<int>(columns - 1 - frame) : 0;
  }
  const int filled = percent * cells / 100;
  std::string line = "glint: ";
  if (cells > 0) {
    line += '[';
    line.append(static_cast<std::size_t>(filled), '#');
    line.append(static_cast<std::size_t>(cells - filled), '.');
    line += "] ";
  }
  line += times;
  if (columns != 0 && line.size() >= columns) line.resize(columns - 1);
  // Blanks overwrite the end of a longer previous line (an ETA in minutes, say).
  const std::size_t length = line.size();
  // Blanks over the rest of a longer previous drawing, within the terminal (it may have shrunk).
  std::size_t pad = barLength_ > length ? barLength_ - length : 0;
  if (columns != 0) pad = std::min(pad, columns - 1 - std::min(length, columns - 1));
  line.append(pad, ' ');
  barLength_ = length;
  emit(stream_, "\r" + line);
  barDrawn_ = true;
}

std::size_t ProgressReporter::terminalColumns() const {
  winsize size{};
  if (ioctl(fileno(stream_), TIOCGWINSZ, &size) != 0) return 0;
  return size.ws_col;
}

void ProgressReporter::printLine(std::size_t done, std::size_t total, double elapsed) {
  emit(stream_,
       fmt::format("glint: {}% (elapsed {}, ETA {})\n", percentOf(done, total),
                   formatDuration(elapsed), formatEta(etaSeconds(done, total, resumed_, elapsed))));
}

}  // namespace glint::cli
