#pragma once
// One ROS-free input interface for Navtech data, with three sources: a TCP socket client, a raw
// capture file of that stream, and the simulator (src/sim/sim_radar_input.cpp). Every source
// yields protocol packets (configuration or one azimuth) through next(); the NavtechDriver turns
// them into scans. All sources share the byte-stream parser, so a capture replays exactly.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "spinradar/driver/capture.hpp"
#include "spinradar/driver/driver_config.hpp"
#include "spinradar/driver/navtech_protocol.hpp"

namespace spinradar::navtech {

enum class InputStatus {
  Ok,            ///< `packet` holds a configuration or an azimuth
  Timeout,       ///< nothing within the timeout (also while waiting to reconnect)
  Disconnected,  ///< the stream broke: discard any rotation in progress; reported once per loss
  End,           ///< a finite source (capture, simulation) has no more data
  Error,         ///< unrecoverable (e.g. unreadable file); see the log
};
const char* toString(InputStatus s);

enum class LogLevel { Debug, Info, Warn, Error };
/// Where inputs report what happened (connects, drops, garbage). Default: stderr.
using LogFn = std::function<void(LogLevel, const std::string&)>;
LogFn stderrLog();

struct Packet {
  enum class Kind { Configuration, Fft } kind = Kind::Fft;
  Configuration config;   ///< Kind::Configuration
  FftData fft;            ///< Kind::Fft (buffers reused)
  int64_t receive_ns = 0; ///< receive time of the bytes that completed the message
};

struct InputStats {
  uint64_t connects = 0;
  uint64_t disconnects = 0;
  uint64_t failed_connects = 0;
  uint64_t malformed = 0;       ///< framed messages whose payload did not decode
  uint64_t keep_alives = 0;
  uint64_t unknown_types = 0;
  StreamStats stream;           ///< parser counters (garbage, oversize, truncation)
};

class RadarInput {
 public:
  virtual ~RadarInput() = default;
  /// Waits at most `timeout` for the next packet.
  virtual InputStatus next(Packet& packet, std::chrono::milliseconds timeout) = 0;
  virtual std::string describe() const = 0;
  virtual InputStats stats() const = 0;
  void setLog(LogFn log) { log_ = log ? std::move(log) : stderrLog(); }

 protected:
  void log(LogLevel l, const std::string& m) const { log_(l, describe() + ": " + m); }
  LogFn log_ = stderrLog();
};

/// Base of the sources that produce raw protocol bytes: frames, decodes, skips keep-alives
/// and unknown types, and counts what it had to throw away.
class ByteStreamInput : public RadarInput {
 public:
  InputStatus next(Packet& packet, std::chrono::milliseconds timeout) override;
  InputStats stats() const override;

 protected:
  /// Reads some bytes into `chunk` (cleared by the caller) and stamps them; may also return
  /// Timeout, Disconnected, End or Error.
  virtual InputStatus readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                               std::chrono::steady_clock::time_point deadline) = 0;
  /// Called for every framed message before decoding (the socket answers a configuration).
  virtual void onMessage(MsgType type) {}
  void resetStream() {
    parser_.reset();
    version_logged_ = false;  // logged again on the next connection
  }

  InputStats stats_;

 private:
  void logFraming();
  StreamParser parser_;
  StreamStats logged_;
  bool version_logged_ = false;
  std::vector<uint8_t> chunk_;
  int64_t chunk_receive_ns_ = 0;
};

int64_t wallClockNs();  ///< CLOCK_REALTIME in ns

struct SocketOptions {
  std::string host = "127.0.0.1";
  int port = kDefaultPort;
  double connect_timeout = 2.0;  ///< s
  double stall_timeout = 2.0;    ///< s without a byte -> reconnect
  double backoff_min = 0.1;      ///< s
  double backoff_max = 5.0;      ///< s
  std::string record_file;       ///< also write a raw capture here when not empty
};

/// TCP client: connects (with timeout), sends Start FFT after the configuration, Stop FFT on
/// close, reconnects with exponential backoff after a refusal, a drop or a stall.
class SocketInput : public ByteStreamInput {
 public:
  explicit SocketInput(SocketOptions options);
  ~SocketInput() override;
  std::string describe() const override;
  void close();  ///< sends Stop FFT and closes; next() reconnects

 protected:
  InputStatus readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                       std::chrono::steady_clock::time_point deadline) override;
  void onMessage(MsgType type) override;

 private:
  void startConnect();
  InputStatus finishConnect(std::chrono::steady_clock::time_point deadline);
  void failConnect(const std::string& why);
  void dropConnection(const std::string& why);
  void sendMessage(MsgType type);

  SocketOptions opt_;
  int fd_ = -1;
  bool connecting_ = false;
  bool started_ = false;
  bool got_config_ = false;
  double backoff_ = 0;
  std::chrono::steady_clock::time_point next_attempt_{};
  std::chrono::steady_clock::time_point last_byte_{};
  std::chrono::steady_clock::time_point connected_at_{};
  std::chrono::steady_clock::time_point connect_deadline_{};
  bool requested_config_ = false;
  CaptureWriter recorder_;
  std::vector<uint8_t> rx_;
};

/// Replays a capture file: deterministic (recorded chunks and receive stamps), as fast as
/// possible (rate 0) or paced at `rate` times the recorded speed.
class CaptureInput : public ByteStreamInput {
 public:
  explicit CaptureInput(const std::string& path, double rate = 0.0);
  std::string describe() const override;

 protected:
  InputStatus readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                       std::chrono::steady_clock::time_point deadline) override;

 private:
  CaptureReader reader_;
  CaptureReader::Record rec_;
  bool pending_ = false;
  double rate_;
  int64_t first_ns_ = -1;
  std::chrono::steady_clock::time_point start_{};
};

/// Builds the socket or capture source from the driver parameters (the simulator source lives
/// in the simulator library: spinradar::sim::makeSimInput).
std::unique_ptr<RadarInput> makeInput(const DriverConfig& config);

}  // namespace spinradar::navtech
