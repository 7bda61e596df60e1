#include <unistd.h>

#include <cmath>

#include "knit/meso/sweep/progress.hpp"

namespace knit::meso::sweep {

Progress::Progress(int total, int already, std::FILE* out, int tty)
    : total_(total), already_(already), out_(out), t0_(std::chrono::steady_clock::now()) {
  tty_ = out_ != nullptr && (tty < 0 ? ::isatty(::fileno(out_)) != 0 : tty == 1);
}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

std::string Progress::clock(double s) {
  if (!std::isfinite(s) || s < 0) return "--:--";
  const long t = std::lround(s);
  char b[32];
  if (t >= 3600)
    std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(b, sizeof b, "%ld:%02ld", t / 60, t % 60);
  return b;
}

void Progress::finished(const std::string& line) {
  ++count_;
  last_ = line;
  if (out_) draw();
}

void Progress::tick() {
  if (!out_ || !tty_) return;
  if (std::chrono::steady_clock::now() - drawn_ >= std::chrono::seconds(1)) draw();
}

void Progress::draw() {
  drawn_ = std::chrono::steady_clock::now();
  const std::string& line = last_;
  const double el = elapsed();
  const double eta = count_ > 0 ? el / count_ * (total_ - count_) : NAN;
  const int all = total_ + already_, now = count_ + already_;
  if (tty_) {
    constexpr int kWidth = 30;
    const int fill = all > 0 ? kWidth * now / all : kWidth;
    std::string bar(static_cast<std::size_t>(fill), '#');
    bar.resize(kWidth, '.');
    std::fprintf(out_, "\r\033[K[%s] %d/%d cases %3d%%  elapsed %s  ETA %s  last: %.60s",
                 bar.c_str(), now, all, all > 0 ? 100 * now / all : 100, clock(el).c_str(),
                 clock(eta).c_str(), line.c_str());
  } else {
    std::fprintf(out_, "[%d/%d] %s  (elapsed %s, ETA %s)\n", now, all, line.c_str(),
                 clock(el).c_str(), clock(eta).c_str());
  }
  std::fflush(out_);
}

void Progress::done() {
  if (out_ && tty_) {
    std::fprintf(out_, "\n");
    std::fflush(out_);
  }
}

}  // namespace knit::meso::sweep
