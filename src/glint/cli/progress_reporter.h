// Render progress on stderr (DESIGN.md §6): a bar redrawn in place on a terminal, plain lines in
// logs.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace glint::cli {

// "0.04 s", "12.3 s", "2 min 05 s", "1 h 02 min".
std::string formatDuration(double seconds);

class ProgressReporter {
 public:
  enum class Style {
    Bar,    // a terminal: one line redrawn with '\r', at most ~10 times a second
    Lines,  // not a terminal: "glint: 25% (elapsed 1.2 s, ETA 3.6 s)" at each 10% or every ~2 s
    Silent  // --quiet
  };

  // The style that suits `stream`: Bar on a terminal, Lines otherwise.
  static Style styleFor(std::FILE* stream);

  ProgressReporter(Style style, std::FILE* stream);

  // Starts the clock (and draws an empty bar). `resumed`: tiles done before the start (copied from
  // a checkpoint), left out of the ETA.
  void start(std::size_t resumed = 0);
  // Tiles done out of total. Calls must not overlap (the renderer serialises them).
  void update(std::size_t done, std::size_t total);
  // Ends the bar's line so that later messages start on a fresh line.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  double elapsedSeconds() const;
  void drawBar(std::size_t done, std::size_t total, double elapsed);
  void printLine(std::size_t done, std::size_t total, double elapsed);
  // The width of the terminal the stream writes to, or 0 when it is not known.
  std::size_t terminalColumns() const;

  Style style_;
  std::FILE* stream_;
  Clock::time_point start_;
  Clock::time_point lastDraw_;
  int lastDecile_ = 0;         // Lines: the last 10% step printed
  bool barDrawn_ = false;      // Bar: something is on the current line
  std::size_t barLength_ = 0;  // Bar: characters of the line drawn last, blanks left out
  bool lastPrinted100_ = false;
  std::size_t resumed_ = 0;
};

}  // namespace glint::cli
