#pragma once
// Progress line for long CLI runs (stderr): rewritten in place on a terminal, one line per
// ~10 % otherwise (logs, CI).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace spinradar::cli {

class Progress {
 public:
  Progress(std::string what, size_t total)
      : what_(std::move(what)), total_(total), tty_(isatty(fileno(stderr)) != 0),
        start_(std::chrono::steady_clock::now()) {}

  /// Call after item `done` (1-based) finished; `note` is appended (e.g. a failure count).
  void update(size_t done, const std::string& note = {}) {
    const double elapsed = secondsSince(start_);
    const double rate = elapsed > 0 ? done / elapsed : 0.0;
    const double eta = rate > 0 ? (total_ - done) / rate : 0.0;
    const bool last = done >= total_;
    if (tty_) {
      if (!last && secondsSince(last_print_) < 0.2) return;
    } else {
      const size_t step = total_ >= 10 ? total_ / 10 : 1;
      if (!last && done % step != 0) return;
    }
    last_print_ = std::chrono::steady_clock::now();
    std::fprintf(stderr, "%s%s %zu/%zu (%.1f/s, %.0f s left)%s%s%s", tty_ ? "\r" : "",
                 what_.c_str(), done, total_, rate, eta, note.empty() ? "" : "  ", note.c_str(),
                 tty_ ? (last ? "\n" : "   ") : "\n");
    std::fflush(stderr);
  }

 private:
  static double secondsSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  std::string what_;
  size_t total_;
  bool tty_;
  std::chrono::steady_clock::time_point start_, last_print_{};
};

}  // namespace spinradar::cli
