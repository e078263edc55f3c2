#pragma once
// A Navtech sensor emulator on a loopback TCP port: sends the configuration on connect,
// streams one FFT message per azimuth after Start FFT Data (at real-time rate or a multiple),
// sends keep-alives, and survives clients connecting, leaving and reconnecting. Fed by any
// scan source (the simulator for `spinradar serve`, synthetic scans in tests). A scriptable
// fault list makes it misbehave on cue for reliability tests.
#include <atomic>
#include <cstdint>
#include <functional>
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
  };
  uint64_t at_azimuth = 0;  ///< applied before FFT message number `at_azimuth` (0-based, global)
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
  TimeByteOrder time_order = TimeByteOrder::Little;
  bool wall_clock = true;         ///< sensor time = wall clock (else the source's stamps as is)
  double keep_alive_period = 1.0; ///< s
  double send_timeout = 2.0;      ///< s a client may block a send before it is dropped
  bool stream_without_start = false;  ///< stream FFT data even before Start FFT Data
  std::vector<ServerFault> faults;    ///< sorted by at_azimuth
  LogFn log;                          ///< default: stderr
};

struct ServerStats {
  uint64_t clients = 0;         ///< connections accepted
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
  bool clientConnected() const { return client_ >= 0; }

 private:
  void run();
  bool openListener();
  void closeClient(const std::string& why);
  bool sendAll(const uint8_t* data, size_t n);
  bool sendAzimuth();
  void readCommands();
  bool applyFaults();
  bool nextScan();
  void sleepFor(double s);
  void log(LogLevel l, const std::string& m) const;

  ServerOptions opt_;
  ScanSource source_;
  Configuration config_;
  bool have_config_ = false;
  PolarScan scan_;
  int row_ = 0;
  int64_t time_offset_ns_ = 0;
  bool time_offset_set_ = false;
  std::vector<uint8_t> out_;
  std::vector<uint16_t> bins16_;
  std::vector<uint8_t> bins8_;
  StreamParser commands_;
  size_t next_fault_ = 0;
  int truncate_next_ = 0;  ///< 1 truncate, 2 corrupt signature
  uint64_t rng_ = 0x9E3779B97F4A7C15ull;

  int listen_fd_ = -1;
  std::atomic<int> client_{-1};
  std::atomic<int> port_{0};
  bool started_stream_ = false;
  std::atomic<bool> running_{false};
  std::atomic<bool> finished_{false};
  std::thread thread_;
  mutable std::mutex stats_mutex_;
  ServerStats stats_;
};

}  // namespace spinradar::navtech
