// Progress of a sweep: on a terminal one bar redrawn in place with the ETA; otherwise (a pipe,
// a log file, CI) one plain line per finished case. The ETA is the mean wall time per finished
// case times the cases left, divided by nothing else: with all workers busy, cases finish at
// the pool's rate, which the mean already reflects (finished / elapsed).
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace knit::meso::sweep {

class Progress {
 public:
  /// `total` cases to run in this session, `already` finished before (resume). out = nullptr:
  /// silent. tty: -1 = detect (isatty), 0 = plain lines, 1 = bar.
  Progress(int total, int already, std::FILE* out, int tty = -1);
  /// One case finished; `line` describes it (shown in plain mode, and as "last:" on the bar).
  void finished(const std::string& line);
  /// On a terminal: redraws the bar (elapsed time, ETA) if the last draw is older than 1 s.
  void tick();
  /// Clears the bar (before other output).
  void done();
  double elapsed() const;
  /// "1:05" / "1:02:03"
  static std::string clock(double seconds);

 private:
  int total_, already_, count_ = 0;
  std::FILE* out_;
  bool tty_;
  std::chrono::steady_clock::time_point t0_, drawn_;
  std::string last_;
  void draw();
};

}  // namespace knit::meso::sweep
