#include "spinradar/driver/navtech_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <cmath>
#include <stdexcept>

namespace spinradar::navtech {

using Clock = std::chrono::steady_clock;

NavtechServer::NavtechServer(ServerOptions options, ScanSource source)
    : opt_(std::move(options)), source_(std::move(source)) {
  if (!opt_.log) opt_.log = stderrLog();
  if (opt_.encoder_phase < 0)
    throw std::invalid_argument("navtech server: encoder_phase = " + std::to_string(opt_.encoder_phase) +
                                " must not be negative");
  if (opt_.max_clients < 1)
    throw std::invalid_argument("navtech server: max_clients = " + std::to_string(opt_.max_clients) +
                                " must be at least 1");
  std::sort(opt_.faults.begin(), opt_.faults.end(),
            [](const ServerFault& a, const ServerFault& b) { return a.at_azimuth < b.at_azimuth; });
  port_ = opt_.port;
}

NavtechServer::~NavtechServer() { stop(); }

void NavtechServer::log(LogLevel l, const std::string& m) const {
  opt_.log(l, "navtech server :" + std::to_string(port_.load()) + ": " + m);
}

ServerStats NavtechServer::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

bool NavtechServer::openListener() {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return false;
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port_));
  if (inet_pton(AF_INET, opt_.bind.c_str(), &addr.sin_addr) != 1 ||
      ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0 ||
      ::listen(listen_fd_, 4) < 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    return false;
  }
  socklen_t len = sizeof addr;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  return true;
}

void NavtechServer::start() {
  if (running_) return;
  if (!openListener())
    throw std::runtime_error("navtech server: cannot listen on " + opt_.bind + ":" +
                             std::to_string(opt_.port) + ": " + std::strerror(errno));
  running_ = true;
  thread_ = std::thread([this] { run(); });
}

void NavtechServer::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
  for (auto& c : clients_)
    if (c->fd >= 0) ::close(c->fd);
  clients_.clear();
  connected_ = 0;
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
}

void NavtechServer::sleepFor(double s) {
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(s));
  while (running_ && Clock::now() < until)
    std::this_thread::sleep_for(std::min<Clock::duration>(until - Clock::now(),
                                                         std::chrono::milliseconds(20)));
}

bool NavtechServer::nextScan() {
  if (!source_(scan_) || scan_.empty()) return false;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.scans_started;
  }
  row_ = 0;
  if (!have_config_) {
    config_.azimuth_samples = uint16_t(scan_.azimuths);
    config_.range_in_bins = uint16_t(scan_.bins);
    config_.bin_size = uint16_t(std::lround(scan_.range_resolution * 1e4));
    config_.encoder_size = uint16_t(scan_.encoder_size);
    config_.rotation_mhz = uint16_t(std::lround(opt_.rotation_hz * 1e3));
    config_.packet_rate = uint16_t(std::lround(opt_.rotation_hz * scan_.azimuths));
    config_.range_offset = float(scan_.range_offset);
    have_config_ = true;
  }
  if (opt_.wall_clock && !time_offset_set_) {
    time_offset_ns_ = wallClockNs() - scan_.firstStamp();
    time_offset_set_ = true;
  }
  return true;
}

bool NavtechServer::applyFaults() {
  const uint64_t k = stats().azimuths_sent;
  while (next_fault_ < opt_.faults.size() && opt_.faults[next_fault_].at_azimuth <= k) {
    const ServerFault f = opt_.faults[next_fault_++];
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.faults_applied;
    }
    out_.clear();
    switch (f.kind) {
      case ServerFault::Kind::Disconnect: closeAll("fault: disconnect"); return false;
      case ServerFault::Kind::Stall: log(LogLevel::Info, "fault: stall"); sleepFor(f.value); break;
      case ServerFault::Kind::Garbage:
        for (int i = 0; i < int(f.value); ++i) {
          rng_ = rng_ * 6364136223846793005ull + 1442695040888963407ull;
          out_.push_back(uint8_t(rng_ >> 56));
        }
        broadcast(out_.data(), out_.size(), false);
        break;
      case ServerFault::Kind::Truncate: truncate_next_ = 1; break;
      case ServerFault::Kind::CorruptSignature: truncate_next_ = 2; break;
      case ServerFault::Kind::Oversized:
        encodeHeader(out_, MsgType::FftData8, uint32_t(f.value));
        broadcast(out_.data(), out_.size(), false);
        break;
      case ServerFault::Kind::NewConfiguration:
        if (f.has_config) config_ = f.config;
        encodeConfiguration(out_, config_);
        broadcast(out_.data(), out_.size(), false);
        break;
      case ServerFault::Kind::Restart:
        closeAll("fault: restart");
        ::close(listen_fd_);
        listen_fd_ = -1;
        log(LogLevel::Info, "fault: restarting (down for " + std::to_string(f.value) + " s)");
        sleepFor(f.value);
        if (f.has_config) config_ = f.config;
        if (!openListener()) log(LogLevel::Error, "cannot listen again after restart");
        return false;
      case ServerFault::Kind::ClockStep:
        clock_step_ns_ += int64_t(std::llround(f.value * 1e9));
        log(LogLevel::Info, "fault: sensor clock steps by " + std::to_string(f.value) + " s");
        break;
      case ServerFault::Kind::Gap: {
        // The sensor keeps turning: the azimuths of the gap are made and thrown away.
        log(LogLevel::Info, "fault: gap of " + std::to_string(f.value) + " s");
        const int64_t skip = std::llround(f.value * std::max(1, int(config_.packet_rate)));
        for (int64_t i = 0; i < skip && running_; ++i)
          if (!nextAzimuth()) return false;
        sleepFor(f.value);
        break;
      }
    }
  }
  return anyStarted();
}

bool NavtechServer::nextAzimuth() {
  // The source's scan is resampled when the configuration differs from it (after a fault);
  // row_ then counts configuration rows. A configuration change mid-scan can leave row_ past
  // the new row count, which ends that scan.
  auto sameShape = [this] {
    return config_.azimuth_samples == scan_.azimuths && config_.range_in_bins == scan_.bins;
  };
  if (row_ >= (sameShape() ? scan_.azimuths : int(config_.azimuth_samples)) && !nextScan())
    return false;
  const int n = config_.azimuth_samples, nb = config_.range_in_bins;
  const bool same = sameShape();
  if (!same && row_ >= n) return false;  // a configuration of 0 rows: nothing to send
  const int src_row = same ? row_ : int(int64_t(row_) * scan_.azimuths / n);
  const uint16_t encoder = uint16_t(
      ((same ? scan_.encoder[row_] : int64_t(row_) * config_.encoder_size / n) + opt_.encoder_phase) %
      std::max<int>(1, config_.encoder_size));
  const int copy = std::min(nb, scan_.bins);
  const uint8_t* src = scan_.row(src_row);
  const int64_t stamp =
      scan_.stamp_ns[src_row] + (opt_.wall_clock ? time_offset_ns_ : 0) + clock_step_ns_;
  out_.clear();
  if (opt_.bit_depth == 16) {
    bins16_.assign(size_t(nb), 0);
    for (int b = 0; b < copy; ++b) bins16_[b] = uint16_t(src[b] << 8);
    encodeFft16(out_, sweep_, encoder, stamp, bins16_.data(), bins16_.size(), opt_.time_order);
  } else {
    bins8_.assign(size_t(nb), 0);
    std::copy(src, src + copy, bins8_.begin());
    encodeFft8(out_, sweep_, encoder, stamp, bins8_.data(), bins8_.size(), opt_.time_order);
  }
  ++sweep_;
  ++row_;
  return true;
}

bool NavtechServer::sendAzimuth() {
  if (!nextAzimuth()) return false;
  size_t len = out_.size();
  if (truncate_next_ == 1) len /= 2;
  if (truncate_next_ == 2) out_[5] ^= 0xFF;
  truncate_next_ = 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.azimuths_sent;
  }
  broadcast(out_.data(), len, true);
  return true;
}

void NavtechServer::run() {
  auto next_due = Clock::now();
  auto next_keep_alive = Clock::now();
  const auto keep_alive = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(opt_.keep_alive_period));
  bool streaming = false;
  while (running_) {
    if (listen_fd_ < 0 && !finished_) openListener();
    if (listen_fd_ >= 0 && !finished_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 0) > 0) acceptClient();
    }
    for (auto& c : clients_) {
      if (c->fd >= 0) readCommands(*c);
      flush(*c);
    }
    removeClosed();
    if (clients_.empty()) {
      streaming = false;
      waitForEvents(20);
      continue;
    }
    const auto now = Clock::now();
    if (now >= next_keep_alive) {
      out_.clear();
      encodeEmpty(out_, MsgType::KeepAlive);
      broadcast(out_.data(), out_.size(), false);
      next_keep_alive = now + keep_alive;
    }
    if (!anyStarted()) {
      streaming = false;
      waitForEvents(20);
      continue;
    }
    if (!streaming) next_due = now;  // the first client to start sets the pace
    streaming = true;
    if (opt_.rate > 0 && now < next_due) {
      const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next_due - now);
      if (wait.count() > 2)
        waitForEvents(int(std::min<int64_t>(wait.count() - 1, 20)));
      else
        std::this_thread::sleep_until(next_due);  // sub-millisecond pacing
      continue;
    }
    if (opt_.rate <= 0 && !allCaughtUp()) {  // as fast as the slowest started client reads
      waitForEvents(20);
      continue;
    }
    if (!applyFaults()) continue;
    if (!sendAzimuth()) {
      finished_ = true;
      drain();
      closeAll("end of the scan source");
      continue;
    }
    if (opt_.rate > 0) {
      const double period = 1.0 / (std::max(1, int(config_.packet_rate)) * opt_.rate);
      next_due += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
      if (Clock::now() - next_due > std::chrono::milliseconds(250)) next_due = Clock::now();
    }
  }
}

}  // namespace spinradar::navtech
