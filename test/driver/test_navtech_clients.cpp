// The sensor emulator against clients other than our driver: a client that sends its commands
// with protocol version byte 0 (as Navtech's SDK examples do), several clients at once each
// with its own start and stop, and a client beyond max_clients (refused, not left hanging).
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <set>
#include <thread>

#include "navtech_test_util.hpp"

using namespace spinradar;
using namespace spinradar::navtech;
using namespace spinradar::navtech::test;
using Clock = std::chrono::steady_clock;

namespace {

// The exact bytes of the SDK example's Start / Stop FFT Data (version byte 0).
std::vector<uint8_t> sdkCommand(uint8_t type) {
  return {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F, 0x1F, 0x1F, 0x3F,
          0x3F, 0x7F, 0x7F, 0xFE, 0xFE, 0x00, type, 0x00, 0x00, 0x00, 0x00};
}

/// A bare TCP client that frames what it reads with the project's parser.
struct RawClient {
  int fd = -1;
  StreamParser parser;
  int configurations = 0, ffts = 0;
  bool closed = false;
  std::set<uint16_t> encoders;

  explicit RawClient(int port) {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(uint16_t(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) closed = true;
  }
  ~RawClient() { ::close(fd); }
  void send(const std::vector<uint8_t>& b) { (void)::send(fd, b.data(), b.size(), MSG_NOSIGNAL); }
  /// Reads for at most `budget_s` or until `done` says so.
  template <class Done>
  void readUntil(double budget_s, Done done) {
    const auto end = Clock::now() + std::chrono::duration<double>(budget_s);
    uint8_t buf[65536];
    while (!closed && !done() && Clock::now() < end) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) {
        closed = true;
        break;
      }
      parser.feed(buf, size_t(n));
      RawMessage m;
      FftData d;
      while (parser.next(m)) {
        if (m.type == uint8_t(MsgType::Configuration)) ++configurations;
        if ((m.type == uint8_t(MsgType::FftData8) || m.type == uint8_t(MsgType::FftData16)) &&
            decodeFft(MsgType(m.type), m.payload, m.size, d)) {
          ++ffts;
          encoders.insert(d.encoder);
        }
      }
    }
  }
};

ServerOptions quietServer(LogSink& log, double rate = 5.0) {
  ServerOptions o;
  o.rate = rate;
  o.log = log.fn();
  return o;
}

}  // namespace

TEST(NavtechClients, StartWithVersionZeroStreamsAFullRotation) {
  LogSink log;
  NavtechServer server(quietServer(log), patternSource());
  server.start();
  RawClient c(server.port());
  c.readUntil(5, [&] { return c.configurations > 0; });
  ASSERT_EQ(c.configurations, 1) << log.all();
  EXPECT_EQ(c.ffts, 0);  // nothing before Start FFT Data
  c.send(sdkCommand(0x15));
  c.readUntil(10, [&] { return c.encoders.size() >= 400; });
  EXPECT_EQ(c.encoders.size(), 400u) << log.all();  // every azimuth of a rotation
  EXPECT_TRUE(log.contains("sends protocol version byte 0 (accepted)")) << log.all();
}

TEST(NavtechClients, TwoClientsAtOnceEachWithItsOwnStartAndStop) {
  LogSink log;
  ServerOptions o = quietServer(log);
  o.max_clients = 2;
  NavtechServer server(o, patternSource());
  server.start();
  // Client A: our driver (version 1 commands). Client B: a raw client speaking version 0.
  NavtechDriver a(fastDriverConfig(server.port()));
  a.setLog([](LogLevel, const std::string&) {});
  AssembledScan s;
  int scans_a = 0;
  const auto end = Clock::now() + std::chrono::seconds(10);
  while (scans_a < 1 && Clock::now() < end)
    scans_a += a.poll(s, std::chrono::milliseconds(100)) == InputStatus::Ok;
  ASSERT_EQ(scans_a, 1) << log.all();
  RawClient b(server.port());
  b.readUntil(5, [&] { return b.configurations > 0; });
  ASSERT_EQ(b.configurations, 1) << log.all();  // served while A streams
  b.send(sdkCommand(0x15));
  b.readUntil(10, [&] { return b.encoders.size() >= 400; });
  EXPECT_EQ(b.encoders.size(), 400u) << log.all();
  EXPECT_EQ(server.clientCount(), 2);

  // A third client is refused at once: the connection closes without a byte.
  RawClient refused(server.port());
  refused.readUntil(5, [] { return false; });
  EXPECT_TRUE(refused.closed);
  EXPECT_EQ(refused.configurations, 0);
  EXPECT_EQ(server.stats().refused_clients, 1u);
  EXPECT_TRUE(log.contains("refused: already serving 2 client(s) (max_clients 2)")) << log.all();

  // B stops: once the quiet sets in, A keeps getting whole rotations and B gets nothing more.
  b.send(sdkCommand(0x16));
  int before = b.ffts;
  for (int i = 0; i < 50; ++i) {  // wait for the messages in flight before the Stop
    b.readUntil(0.1, [] { return false; });
    if (b.ffts == before) break;
    before = b.ffts;
  }
  const int after_stop = b.ffts;
  int more_a = 0;
  const auto end2 = Clock::now() + std::chrono::seconds(10);
  while (more_a < 3 && Clock::now() < end2) {
    if (a.poll(s, std::chrono::milliseconds(100)) == InputStatus::Ok) {
      EXPECT_TRUE(wellFormed(s));
      ++more_a;
    }
  }
  EXPECT_EQ(more_a, 3);
  b.readUntil(0.2, [] { return false; });
  EXPECT_EQ(b.ffts, after_stop);
  EXPECT_FALSE(b.closed);
  EXPECT_EQ(a.stats().input.disconnects, 0u);
}
