#pragma once
// The one checked conversion for integers read from files and file names (stamps, frame numbers,
// counts): malformed or out-of-range text and int64 overflow become a `false` or a named
// std::runtime_error, never undefined behaviour or a silently wrapped stamp.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

namespace spinradar {

/// Decimal integer (optional leading '-', digits only) into int64. False when the text is empty,
/// holds anything else, or does not fit (more than 19 digits, above 9223372036854775807).
inline bool parseInt64(std::string_view text, int64_t& out) {
  bool neg = false;
  size_t i = 0;
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    neg = text[0] == '-';
    i = 1;
  }
  if (i >= text.size()) return false;
  uint64_t v = 0;
  const uint64_t limit = neg ? uint64_t(std::numeric_limits<int64_t>::max()) + 1
                             : uint64_t(std::numeric_limits<int64_t>::max());
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c < '0' || c > '9') return false;
    const uint64_t d = uint64_t(c - '0');
    if (v > (limit - d) / 10) return false;
    v = v * 10 + d;
  }
  out = neg ? int64_t(0 - v) : int64_t(v);
  return true;
}

/// a * b; throws std::runtime_error "<what>: <a> x <b> does not fit in 64 bits" on overflow.
inline int64_t mulChecked(int64_t a, int64_t b, const std::string& what) {
  int64_t r = 0;
  if (__builtin_mul_overflow(a, b, &r))
    throw std::runtime_error(what + ": " + std::to_string(a) + " x " + std::to_string(b) +
                             " does not fit in 64 bits (stamp or count out of range)");
  return r;
}

/// a + b; throws like mulChecked on overflow.
inline int64_t addChecked(int64_t a, int64_t b, const std::string& what) {
  int64_t r = 0;
  if (__builtin_add_overflow(a, b, &r))
    throw std::runtime_error(what + ": " + std::to_string(a) + " + " + std::to_string(b) +
                             " does not fit in 64 bits (stamp or count out of range)");
  return r;
}

/// A finite double rounded to int64; throws std::runtime_error naming `what` when it is not
/// finite or outside the int64 range.
inline int64_t roundToInt64Checked(double v, const std::string& what) {
  // 2^63 is exactly representable; anything >= it (or NaN) does not fit.
  if (!(std::fabs(v) < 9223372036854775808.0)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    throw std::runtime_error(what + ": " + buf + " does not fit in 64 bits (stamp or count out of range)");
  }
  return static_cast<int64_t>(std::llround(v));
}

/// Decimal seconds "1574859771.744660272" into ns exactly (no double rounding; digits after the
/// ninth are ignored). False when malformed or out of the int64 ns range (about 292 years).
inline bool parseSecondsToNs(std::string_view text, int64_t& ns) {
  const size_t dot = text.find('.');
  int64_t sec = 0;
  if (!parseInt64(text.substr(0, dot), sec)) return false;
  int64_t frac = 0;
  if (dot != std::string_view::npos) {
    std::string f(text.substr(dot + 1, 9));
    for (char c : text.substr(dot + 1))
      if (c < '0' || c > '9') return false;
    f.resize(9, '0');
    if (!parseInt64(f, frac)) return false;
    if (!text.empty() && text[0] == '-') frac = -frac;
  }
  int64_t r = 0;
  if (__builtin_mul_overflow(sec, int64_t(1000000000), &r) || __builtin_add_overflow(r, frac, &r))
    return false;
  ns = r;
  return true;
}

}  // namespace spinradar
