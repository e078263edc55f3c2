#pragma once
// A Navtech sensor emulator on a loopback TCP port. Like a real radar it serves several clients
// at once (up to ServerOptions::max_clients): each gets the configuration on connect and on
// request, and FFT messages between its own Start and Stop FFT Data; all share one turning
// sensor (one azimuth stream at real-time rate or a multiple). Commands are accepted whatever
// their protocol version byte (Navtech's SDK examples send 0). Keep-alives, clients leaving and
// reconnecting, slow clients (dropped after send_timeout, never stalling the others). Fed by
// any scan source (the simulator for `spinradar serve`, synthetic scans in tests). A scriptable
// fault list makes it misbehave on cue for reliability tests.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "spinradar/driver/navtech_protocol.hpp"
#include "spinradar/core/polar_scan.hpp"
#include "spinradar/driver/radar_input.hpp"

namespace spinradar::navtech {

/// Fills the next rotation; returns false when there is no more (the server then closes).
using ScanSource = std::function<bool(PolarScan&)>;

struct ServerFault {
  enum class Kind {
    Disconnect,        ///< close the client connection
    Stall,             ///< send nothing (not even keep-alives) for `value` s
    Garbage,           ///< send `value` random bytes
    Truncate,          ///< send only the first half of the next message
    CorruptSignature,  ///< flip a signature byte of the next message
    Oversized,         ///< send a header announcing `value` bytes of payload, and no payload
    NewConfiguration,  ///< switch to `config` and send it mid-stream
    Restart,           ///< drop the client, refuse connections for `value` s, come back with `config`
    ClockStep,         ///< the sensor clock reads `value` s later from now on (negative: steps back)
    Gap,               ///< the sensor turns on but sends nothing (no keep-alive) for `value` s
  };
  uint64_t at_azimuth = 0;  ///< applied before FFT message number `at_azimuth` (0-based, global)
  /// Faults apply to every connected client (Disconnect and Restart drop them all).
  Kind kind = Kind::Disconnect;
  double value = 0;
  bool has_config = false;
  Configuration config;
};

struct ServerOptions {
  std::string bind = "127.0.0.1";
  int port = 0;                   ///< 0: pick a free port (see NavtechServer::port())
  double rate = 1.0;              ///< multiple of real time; 0 = as fast as the client reads
  double rotation_hz = 4.0;       ///< sets the configuration's rotation speed and packet rate
  int bit_depth = 8;              ///< 8: type 30 messages; 16: type 31 (value = power * 256)
  /// Counts added to every reported encoder value, below one azimuth step (the rows are not
  /// moved: a reported-angle offset). A real CIR204-H reports 13, 27, ..., 5599 (phase 13);
  /// clients that turn encoders into rows with int() need a phase > 0 (Navtech's examples).
  int encoder_phase = 0;
  TimeByteOrder time_order = TimeByteOrder::Little;
  bool wall_clock = true;         ///< sensor time = wall clock (else the source's stamps as is)
  double keep_alive_period = 1.0; ///< s
  double send_timeout = 2.0;      ///< s a client may take nothing before it is dropped
  bool stream_without_start = false;  ///< stream FFT data even before Start FFT Data
  /// Clients served at once (the `serve --max-clients` option reads its default here). One
  /// more is accepted, logged as refused and closed at once, so it is never left hanging.
  int max_clients = 4;
  std::vector<ServerFault> faults;    ///< sorted by at_azimuth
  LogFn log;                          ///< default: stderr
};

struct ServerStats {
  uint64_t clients = 0;         ///< connections accepted
  uint64_t refused_clients = 0; ///< connections closed at once (max_clients reached)
  uint64_t azimuths_sent = 0;   ///< FFT messages sent (global counter used by faults)
  uint64_t scans_started = 0;   ///< rotations taken from the source
  uint64_t faults_applied = 0;
  uint64_t dropped_clients = 0; ///< clients dropped for not reading (slow consumer)
};

class NavtechServer {
 public:
  NavtechServer(ServerOptions options, ScanSource source);
  ~NavtechServer();  ///< stops and joins
  NavtechServer(const NavtechServer&) = delete;
  NavtechServer& operator=(const NavtechServer&) = delete;

  void start();  ///< binds (throws std::runtime_error naming the port) and starts the thread
  void stop();
  int port() const { return port_; }
  ServerStats stats() const;
  bool finished() const { return finished_; }  ///< the source ran out
  bool clientConnected() const { return connected_ > 0; }
  int clientCount() const { return connected_; }

 private:
  struct Client {
    int fd = -1;
    uint64_t id = 0;
    std::string peer;
    StreamParser commands;
    bool started = false;
    bool version_logged = false;
    std::deque<std::vector<uint8_t>> queue;  ///< whole messages not handed to the kernel yet
    size_t head_sent = 0;                    ///< bytes of queue.front() already handed over
    size_t queued_bytes = 0;
    std::chrono::steady_clock::time_point blocked_since{};  ///< last progress
  };

  void run();
  bool openListener();
  void acceptClient();
  void closeClient(Client& c, const std::string& why);
  void closeAll(const std::string& why);
  void removeClosed();
  void send(Client& c, const uint8_t* data, size_t n);
  void flush(Client& c);
  void broadcast(const uint8_t* data, size_t n, bool started_only);
  int unsent(const Client& c) const;  ///< bytes the kernel holds unsent (window-limited)
  void drain();  ///< sends what is pending (at most send_timeout), e.g. before closing
  void sendConfiguration(Client& c);
  bool anyStarted() const;
  bool allCaughtUp() const;  ///< no started client has messages waiting
  void waitForEvents(int timeout_ms);
  bool sendAzimuth();
  bool nextAzimuth();  ///< encodes the next azimuth into out_ and advances; false at the end
  void readCommands(Client& c);
  bool applyFaults();
  bool nextScan();
  void sleepFor(double s);
  void log(LogLevel l, const std::string& m) const;

  static constexpr size_t kMaxQueued = 16u << 20;  ///< a client further behind is dropped
  ServerOptions opt_;
  ScanSource source_;
  Configuration config_;
  bool have_config_ = false;
  PolarScan scan_;
  int row_ = 0;
  int64_t time_offset_ns_ = 0;
  bool time_offset_set_ = false;
  int64_t clock_step_ns_ = 0;  ///< ClockStep faults so far
  uint16_t sweep_ = 0;         ///< the FFT messages' counter (runs on through a Gap)
  std::vector<uint8_t> out_;
  std::vector<uint16_t> bins16_;
  std::vector<uint8_t> bins8_;
  size_t next_fault_ = 0;
  int truncate_next_ = 0;  ///< 1 truncate, 2 corrupt signature
  uint64_t rng_ = 0x9E3779B97F4A7C15ull;

  int listen_fd_ = -1;
  std::vector<std::unique_ptr<Client>> clients_;
  std::atomic<int> connected_{0};
  std::atomic<int> port_{0};
  std::atomic<bool> running_{false};
  std::atomic<bool> finished_{false};
  std::thread thread_;
  mutable std::mutex stats_mutex_;
  ServerStats stats_;
};

}  // namespace spinradar::navtech
