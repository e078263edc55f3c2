#pragma once
// Shared helpers of the Navtech loopback tests: a synthetic scan source whose rows carry a
// checkable pattern, a scan checker that detects shifted or mixed rows, a log collector.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>

#include <mutex>
#include <string>
#include <vector>

#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/driver/navtech_server.hpp"

namespace spinradar::navtech::test {

/// Row a of rotation k: power[b] = (7k + 3a + b) mod 256; stamps at 4 Hz from t = 100 s.
inline ScanSource patternSource(int azimuths = 400, int bins = 64, int max_scans = -1) {
  auto k = std::make_shared<int>(0);
  return [=](PolarScan& s) {
    if (max_scans >= 0 && *k >= max_scans) return false;
    s.resize(azimuths, bins);
    s.encoder_size = 5600;
    s.range_resolution = 0.0438;
    for (int a = 0; a < azimuths; ++a) {
      s.encoder[a] = uint16_t(a * 5600 / azimuths);
      s.stamp_ns[a] = 100'000'000'000 + (int64_t(*k) * azimuths + a) * 250'000'000 / azimuths;
      for (int b = 0; b < bins; ++b) s.row(a)[b] = uint8_t(7 * *k + 3 * a + b);
    }
    ++*k;
    return true;
  };
}

/// A scan is well formed when every valid row holds one whole row of one rotation at the right
/// place: row[b] - row[0] == b and row[0] - 3a is the same for all valid rows.
inline ::testing::AssertionResult wellFormed(const AssembledScan& s) {
  const PolarScan& p = s.scan;
  if (p.azimuths <= 0 || p.bins <= 0 || p.power.size() != size_t(p.azimuths) * p.bins ||
      p.valid.size() != size_t(p.azimuths) || p.stamp_ns.size() != size_t(p.azimuths))
    return ::testing::AssertionFailure() << "inconsistent sizes";
  int key = -1, valid = 0;
  for (int a = 0; a < p.azimuths; ++a) {
    if (!p.valid[a]) continue;
    ++valid;
    const uint8_t* r = p.row(a);
    const int row_of_encoder = int((int64_t(p.encoder[a]) * p.azimuths + p.encoder_size / 2) /
                                   p.encoder_size);
    if (row_of_encoder != a) return ::testing::AssertionFailure() << "row " << a << " encoder " << p.encoder[a];
    for (int b = 0; b < p.bins; ++b)
      if (uint8_t(r[b] - r[0]) != uint8_t(b))
        return ::testing::AssertionFailure() << "row " << a << " bin " << b << " garbled";
    // Rows are resampled by the server after a configuration change; compare per source row.
    const int k = uint8_t(r[0] - 3 * (a * 400 / p.azimuths));
    if (key < 0) key = k;
    if (k != key) return ::testing::AssertionFailure() << "row " << a << " from another rotation";
  }
  if (valid == 0) return ::testing::AssertionFailure() << "no valid row";
  return ::testing::AssertionSuccess();
}

struct LogSink {
  std::mutex m;
  std::vector<std::string> lines;
  LogFn fn() {
    return [this](LogLevel, const std::string& s) {
      std::lock_guard<std::mutex> lock(m);
      lines.push_back(s);
    };
  }
  bool contains(const std::string& needle) {
    std::lock_guard<std::mutex> lock(m);
    for (auto& l : lines)
      if (l.find(needle) != std::string::npos) return true;
    return false;
  }
  std::string all() {
    std::lock_guard<std::mutex> lock(m);
    std::string s;
    for (auto& l : lines) s += l + "\n";
    return s;
  }
};

inline DriverConfig fastDriverConfig(int port) {
  DriverConfig c;
  c.port = port;
  c.connect_timeout = 0.5;
  c.stall_timeout = 0.4;
  c.backoff_min = 0.05;
  c.backoff_max = 0.4;
  return c;
}

/// A loopback port that is free right now (bound then released).
inline int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return ntohs(addr.sin_port);
}

}  // namespace spinradar::navtech::test
