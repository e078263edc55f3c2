// NavtechServer, the client side: accepting (up to max_clients, refusing the next with a log
// line), commands of each client (any protocol version byte), non-blocking sends with a
// whole messages only, so a slow client misses messages (and is dropped when it takes nothing)
// without stalling the others.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <linux/sockios.h>
#include <sys/ioctl.h>
#include <linux/sockios.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "spinradar/driver/navtech_server.hpp"

namespace spinradar::navtech {

using Clock = std::chrono::steady_clock;

void NavtechServer::acceptClient() {
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len,
                           SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (fd < 0) return;
  char ip[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &addr.sin_addr, ip, sizeof ip);
  const std::string peer = std::string(ip) + ":" + std::to_string(ntohs(addr.sin_port));
  if (int(clients_.size()) >= opt_.max_clients) {
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.refused_clients;
    }
    log(LogLevel::Warn, "client " + peer + " refused: already serving " +
                            std::to_string(clients_.size()) + " client(s) (max_clients " +
                            std::to_string(opt_.max_clients) + ")");
    ::close(fd);  // refused at once: the client sees the connection close, never a silent hang
    return;
  }
  if (!have_config_ && (row_ = 0, !nextScan())) {
    ::close(fd);
    finished_ = true;
    log(LogLevel::Info, "client " + peer + " closed: no data to serve");
    return;
  }
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  auto c = std::make_unique<Client>();
  c->fd = fd;
  c->peer = peer;
  c->started = opt_.stream_without_start;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    c->id = ++stats_.clients;
  }
  clients_.push_back(std::move(c));
  ++connected_;
  log(LogLevel::Info, "client " + std::to_string(clients_.back()->id) + " (" + peer +
                          ") connected, " + std::to_string(clients_.size()) + " of at most " +
                          std::to_string(opt_.max_clients));
  sendConfiguration(*clients_.back());
}

void NavtechServer::closeClient(Client& c, const std::string& why) {
  if (c.fd < 0) return;
  ::close(c.fd);
  c.fd = -1;
  --connected_;
  log(LogLevel::Info, "client " + std::to_string(c.id) + " left: " + why);
}

void NavtechServer::closeAll(const std::string& why) {
  for (auto& c : clients_) closeClient(*c, why);
  removeClosed();
}

void NavtechServer::removeClosed() {
  clients_.erase(std::remove_if(clients_.begin(), clients_.end(),
                                [](const std::unique_ptr<Client>& c) { return c->fd < 0; }),
                 clients_.end());
}

void NavtechServer::send(Client& c, const uint8_t* data, size_t n) {
  if (c.fd < 0 || n == 0) return;
  if (c.queue.empty()) c.blocked_since = Clock::now();
  c.queue.emplace_back(data, data + n);
  c.queued_bytes += n;
  flush(c);
}

int NavtechServer::unsent(const Client& c) const {
  int n = 0;
  return ioctl(c.fd, SIOCOUTQNSD, &n) == 0 ? n : 0;
}

void NavtechServer::flush(Client& c) {
  // Messages leave one at a time, each once the kernel has sent all before it: then a
  // window-limited socket never holds a message in pieces, and a client a few messages behind
  // (Navtech's Python example reads slower than 1600 azimuths/s and cannot cope with a short
  // recv()) never meets half a message.
  while (c.fd >= 0 && !c.queue.empty()) {
    if (c.head_sent == 0 && unsent(c) > 0) break;
    const std::vector<uint8_t>& m = c.queue.front();
    const ssize_t k = ::send(c.fd, m.data() + c.head_sent, m.size() - c.head_sent,
                             MSG_NOSIGNAL | MSG_DONTWAIT);
    if (k < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
      return closeClient(c, std::string("send: ") + std::strerror(errno));
    if (k <= 0) break;
    c.blocked_since = Clock::now();
    c.head_sent += size_t(k);
    if (c.head_sent < m.size()) break;
    c.queued_bytes -= m.size();
    c.head_sent = 0;
    c.queue.pop_front();
  }
  if (c.fd < 0 || c.queue.empty()) return;
  const double blocked = std::chrono::duration<double>(Clock::now() - c.blocked_since).count();
  if (blocked > opt_.send_timeout || c.queued_bytes > kMaxQueued) {
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.dropped_clients;
    }
    closeClient(c, "not reading for " + std::to_string(opt_.send_timeout) + " s (slow consumer)");
  }
}

void NavtechServer::broadcast(const uint8_t* data, size_t n, bool started_only) {
  for (auto& c : clients_)
    if (c->fd >= 0 && (c->started || !started_only)) send(*c, data, n);
}

void NavtechServer::sendConfiguration(Client& c) {
  out_.clear();
  encodeConfiguration(out_, config_);
  send(c, out_.data(), out_.size());
}

void NavtechServer::drain() {
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(opt_.send_timeout));
  for (;;) {
    bool pending = false;
    for (auto& c : clients_) {
      flush(*c);
      pending = pending || (c->fd >= 0 && !c->queue.empty());
    }
    if (!pending || !running_ || Clock::now() >= until) return;
    waitForEvents(20);
  }
}

bool NavtechServer::anyStarted() const {
  for (auto& c : clients_)
    if (c->fd >= 0 && c->started) return true;
  return false;
}

bool NavtechServer::allCaughtUp() const {
  for (auto& c : clients_)
    if (c->fd >= 0 && c->started && !c->queue.empty()) return false;
  return true;
}

void NavtechServer::waitForEvents(int timeout_ms) {
  std::vector<pollfd> fds;
  if (listen_fd_ >= 0) fds.push_back({listen_fd_, POLLIN, 0});
  for (auto& c : clients_)
    if (c->fd >= 0) fds.push_back({c->fd, short(POLLIN | (c->queue.empty() ? 0 : POLLOUT)), 0});
  if (fds.empty())
    std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));
  else
    ::poll(fds.data(), fds.size(), timeout_ms);
}

void NavtechServer::readCommands(Client& c) {
  uint8_t buf[512];
  for (;;) {
    const ssize_t n = ::recv(c.fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n == 0) return closeClient(c, "closed by the client");
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
        return closeClient(c, std::string("recv: ") + std::strerror(errno));
      break;
    }
    c.commands.feed(buf, size_t(n));
  }
  RawMessage m;
  while (c.fd >= 0 && c.commands.next(m)) {
    if (!c.version_logged) {  // real radars answer any version byte; say which one came
      c.version_logged = true;
      log(LogLevel::Info, "client " + std::to_string(c.id) + " sends protocol version byte " +
                              std::to_string(m.version) +
                              (m.version == kProtocolVersion ? "" : " (accepted)"));
    }
    if (m.type == uint8_t(MsgType::StartFftData)) {
      c.started = true;
    } else if (m.type == uint8_t(MsgType::StopFftData)) {
      c.started = false;
    } else if (m.type == uint8_t(MsgType::ConfigurationRequest) && have_config_) {
      sendConfiguration(c);
    }
  }
}

}  // namespace spinradar::navtech
