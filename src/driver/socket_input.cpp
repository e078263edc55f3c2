// TCP client of a Navtech radar (RadarInput over a socket), non-blocking throughout so that
// every call returns by its deadline: connect, reconnect with backoff, stall detection.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <thread>

#include "spinradar/driver/radar_input.hpp"

namespace spinradar::navtech {

using Clock = std::chrono::steady_clock;

namespace {
int msUntil(Clock::time_point t) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t - Clock::now()).count();
  return int(std::clamp<int64_t>(ms, 0, 1000000));
}
Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}
std::string fmt(double v) {
  std::ostringstream o;
  o.precision(3);
  o << v;
  return o.str();
}
}  // namespace

SocketInput::SocketInput(SocketOptions options) : opt_(std::move(options)) {
  if (!opt_.record_file.empty()) recorder_.open(opt_.record_file);
}

SocketInput::~SocketInput() { close(); }

std::string SocketInput::describe() const {
  return "navtech " + opt_.host + ":" + std::to_string(opt_.port);
}

void SocketInput::sendMessage(MsgType type) {
  if (fd_ < 0) return;
  std::vector<uint8_t> msg;
  encodeEmpty(msg, type);
  // Best effort: a 22-byte message fits any socket buffer; a dead peer is found by recv().
  (void)::send(fd_, msg.data(), msg.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

void SocketInput::close() {
  if (fd_ >= 0) {
    if (started_ && !connecting_) sendMessage(MsgType::StopFftData);
    ::close(fd_);
    if (recorder_.isOpen()) recorder_.writeDisconnect(wallClockNs());
  }
  fd_ = -1;
  connecting_ = started_ = got_config_ = requested_config_ = false;
}

void SocketInput::failConnect(const std::string& why) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  connecting_ = false;
  ++stats_.failed_connects;
  backoff_ = backoff_ > 0 ? std::min(backoff_ * 2, opt_.backoff_max) : opt_.backoff_min;
  next_attempt_ = Clock::now() + seconds(backoff_);
  log(LogLevel::Warn, "connect failed: " + why + "; retrying in " + fmt(backoff_) + " s");
}

void SocketInput::dropConnection(const std::string& why) {
  const bool delivered = got_config_;
  close();
  ++stats_.disconnects;
  // Reset the backoff only after a connection that worked; a sensor that accepts and drops at
  // once gets the same growing delay as one that refuses.
  if (delivered) backoff_ = 0;
  backoff_ = backoff_ > 0 ? std::min(backoff_ * 2, opt_.backoff_max) : opt_.backoff_min;
  next_attempt_ = Clock::now() + seconds(backoff_);
  log(LogLevel::Warn, "connection lost: " + why + "; reconnecting in " + fmt(backoff_) + " s");
}

void SocketInput::startConnect() {
  addrinfo hints{}, *res = nullptr;
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  const int rc = getaddrinfo(opt_.host.c_str(), std::to_string(opt_.port).c_str(), &hints, &res);
  if (rc != 0 || !res) {
    failConnect(std::string("cannot resolve host: ") + gai_strerror(rc));
    return;
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    freeaddrinfo(res);
    failConnect(std::string("socket: ") + std::strerror(errno));
    return;
  }
  const int one = 1;
  setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  const int r = ::connect(fd_, res->ai_addr, res->ai_addrlen);
  freeaddrinfo(res);
  if (r < 0 && errno != EINPROGRESS) {
    failConnect(std::strerror(errno));
    return;
  }
  connecting_ = true;
  connect_deadline_ = Clock::now() + seconds(opt_.connect_timeout);
}

InputStatus SocketInput::finishConnect(Clock::time_point deadline) {
  pollfd p{fd_, POLLOUT, 0};
  const auto until = std::min(deadline, connect_deadline_);
  const int r = ::poll(&p, 1, msUntil(until));
  if (r == 0) {
    if (Clock::now() >= connect_deadline_)
      failConnect("no answer within " + fmt(opt_.connect_timeout) + " s");
    return InputStatus::Timeout;
  }
  int err = 0;
  socklen_t len = sizeof err;
  if (r < 0 || getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len) < 0 || err != 0) {
    failConnect(std::strerror(err ? err : errno));
    return InputStatus::Timeout;
  }
  connecting_ = false;
  connected_at_ = last_byte_ = Clock::now();
  ++stats_.connects;
  resetStream();
  if (recorder_.isOpen()) recorder_.writeConnect(wallClockNs());
  log(LogLevel::Info, "connected; waiting for the configuration");
  return InputStatus::Ok;
}

void SocketInput::onMessage(MsgType type) {
  if (type != MsgType::Configuration) return;
  got_config_ = true;
  backoff_ = 0;
  if (!started_) {
    sendMessage(MsgType::StartFftData);
    started_ = true;
    log(LogLevel::Info, "configuration received; sent Start FFT Data");
  } else {
    log(LogLevel::Info, "new configuration received mid-stream");
  }
}

InputStatus SocketInput::readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                                  Clock::time_point deadline) {
  for (;;) {
    if (fd_ < 0) {
      if (Clock::now() < next_attempt_) {
        std::this_thread::sleep_until(std::min(deadline, next_attempt_));
        if (Clock::now() < next_attempt_) return InputStatus::Timeout;
      }
      startConnect();
      if (fd_ < 0) return InputStatus::Timeout;
    }
    if (connecting_) {
      if (finishConnect(deadline) != InputStatus::Ok) return InputStatus::Timeout;
    }
    // A sensor that accepted but sent no configuration within a second is asked for it once.
    if (!got_config_ && !requested_config_ && Clock::now() - connected_at_ > std::chrono::seconds(1)) {
      sendMessage(MsgType::ConfigurationRequest);
      requested_config_ = true;
    }
    const auto stall_at = last_byte_ + seconds(opt_.stall_timeout);
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, msUntil(std::min(deadline, stall_at)));
    if (r < 0 && errno != EINTR) {
      dropConnection(std::string("poll: ") + std::strerror(errno));
      return InputStatus::Disconnected;
    }
    if (r <= 0) {
      if (Clock::now() >= stall_at) {
        dropConnection("no data for " + fmt(opt_.stall_timeout) + " s (stalled stream)");
        return InputStatus::Disconnected;
      }
      if (Clock::now() >= deadline) return InputStatus::Timeout;
      continue;
    }
    rx_.resize(65536);  // allocated once
    const ssize_t n = ::recv(fd_, rx_.data(), rx_.size(), MSG_DONTWAIT);
    if (n > 0) {
      chunk.assign(rx_.data(), rx_.data() + n);
      receive_ns = wallClockNs();
      last_byte_ = Clock::now();
      if (recorder_.isOpen()) recorder_.writeChunk(receive_ns, chunk.data(), chunk.size());
      return InputStatus::Ok;
    }
    chunk.clear();
    if (n == 0) {
      dropConnection("closed by the sensor");
      return InputStatus::Disconnected;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
    dropConnection(std::string("recv: ") + std::strerror(errno));
    return InputStatus::Disconnected;
  }
}

}  // namespace spinradar::navtech
