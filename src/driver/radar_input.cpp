#include "spinradar/driver/radar_input.hpp"

#include <ctime>
#include <iostream>
#include <thread>

namespace spinradar::navtech {

const char* toString(InputStatus s) {
  switch (s) {
    case InputStatus::Ok: return "ok";
    case InputStatus::Timeout: return "timeout";
    case InputStatus::Disconnected: return "disconnected";
    case InputStatus::End: return "end";
    case InputStatus::Error: return "error";
  }
  return "?";
}

LogFn stderrLog() {
  return [](LogLevel level, const std::string& m) {
    static const char* names[] = {"debug", "info", "warn", "error"};
    if (level == LogLevel::Debug) return;
    std::cerr << "[spinradar driver " << names[int(level)] << "] " << m << std::endl;
  };
}

int64_t wallClockNs() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

InputStats ByteStreamInput::stats() const {
  InputStats s = stats_;
  s.stream = parser_.stats();
  return s;
}

InputStatus ByteStreamInput::next(Packet& packet, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    RawMessage m;
    while (parser_.next(m)) {
      const auto type = MsgType(m.type);
      if (!version_logged_) {  // any version is accepted; say which one this sensor sends
        version_logged_ = true;
        log(LogLevel::Info, "protocol version byte " + std::to_string(m.version) +
                                (m.version == kProtocolVersion ? "" : " (accepted)"));
      }
      onMessage(type);
      packet.receive_ns = chunk_receive_ns_;
      switch (type) {
        case MsgType::Configuration:
          if (decodeConfiguration(m.payload, m.size, packet.config)) {
            packet.kind = Packet::Kind::Configuration;
            return InputStatus::Ok;
          }
          ++stats_.malformed;
          log(LogLevel::Warn, "configuration message too short (" + std::to_string(m.size) +
                                  " bytes): ignored");
          break;
        case MsgType::FftData8:
        case MsgType::FftData16:
          if (decodeFft(type, m.payload, m.size, packet.fft)) {
            packet.kind = Packet::Kind::Fft;
            return InputStatus::Ok;
          }
          if (stats_.malformed++ % 1000 == 0)
            log(LogLevel::Warn, "malformed FFT message (" + std::to_string(m.size) +
                                    " bytes) skipped; " + std::to_string(stats_.malformed) +
                                    " so far");
          break;
        case MsgType::KeepAlive: ++stats_.keep_alives; break;
        case MsgType::ConfigurationRequest:
        case MsgType::StartFftData:
        case MsgType::StopFftData: break;  // client-to-sensor messages: nothing to do
        default:
          if (stats_.unknown_types++ % 1000 == 0)
            log(LogLevel::Warn, "skipping message of unknown type " + std::to_string(m.type) + " (" +
                                    std::to_string(stats_.unknown_types) + " so far)");
      }
    }
    logFraming();
    chunk_.clear();
    const InputStatus st = readSome(chunk_, chunk_receive_ns_, deadline);
    if (st == InputStatus::Disconnected) resetStream();
    if (st != InputStatus::Ok) return st;
    parser_.feed(chunk_.data(), chunk_.size());
  }
}

void ByteStreamInput::logFraming() {
  // One line per kind of framing problem per read, with running totals.
  const StreamStats& now = parser_.stats();
  if (now.resyncs > logged_.resyncs)
    log(LogLevel::Warn, "garbage in stream: resynchronised on the signature (" +
                            std::to_string(now.garbage_bytes - logged_.garbage_bytes) +
                            " bytes skipped, " + std::to_string(now.resyncs) + " resyncs so far)");
  if (now.oversized > logged_.oversized)
    log(LogLevel::Warn, "refused header(s) announcing a payload over 1 MB (" +
                            std::to_string(now.oversized) + " so far)");
  if (now.truncated > logged_.truncated)
    log(LogLevel::Warn, "message cut short by a new header: dropped (" +
                            std::to_string(now.truncated) + " so far)");
  logged_ = now;
}

// ---- capture replay ----

CaptureInput::CaptureInput(const std::string& path, double rate) : reader_(path), rate_(rate) {}

std::string CaptureInput::describe() const { return "capture " + reader_.path(); }

InputStatus CaptureInput::readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                                   std::chrono::steady_clock::time_point deadline) {
  for (;;) {
    if (!pending_) {
      try {
        if (!reader_.next(rec_)) return InputStatus::End;
      } catch (const std::exception& e) {
        log(LogLevel::Error, e.what());
        return InputStatus::Error;
      }
      pending_ = true;
    }
    if (rate_ > 0) {
      if (first_ns_ < 0) {
        first_ns_ = rec_.receive_ns;
        start_ = std::chrono::steady_clock::now();
      }
      const auto due = start_ + std::chrono::nanoseconds(
                                    int64_t(double(rec_.receive_ns - first_ns_) / rate_));
      if (due > deadline) {
        std::this_thread::sleep_until(deadline);
        return InputStatus::Timeout;
      }
      std::this_thread::sleep_until(due);
    }
    pending_ = false;
    switch (rec_.kind) {
      case CaptureReader::Kind::Data:
        chunk.swap(rec_.data);
        receive_ns = rec_.receive_ns;
        return InputStatus::Ok;
      case CaptureReader::Kind::Disconnect:
        ++stats_.disconnects;
        log(LogLevel::Info, "recorded disconnect");
        return InputStatus::Disconnected;
      case CaptureReader::Kind::Connect: ++stats_.connects; break;
      case CaptureReader::Kind::End: return InputStatus::End;
    }
  }
}

std::unique_ptr<RadarInput> makeInput(const DriverConfig& c) {
  if (c.input == "socket") {
    SocketOptions o;
    o.host = c.host;
    o.port = c.port;
    o.connect_timeout = c.connect_timeout;
    o.stall_timeout = c.stall_timeout;
    o.backoff_min = c.backoff_min;
    o.backoff_max = c.backoff_max;
    o.record_file = c.record_file;
    return std::make_unique<SocketInput>(o);
  }
  if (c.input == "capture") {
    if (c.capture_file.empty())
      throw std::invalid_argument("parameter 'capture_file' is required with input 'capture'");
    return std::make_unique<CaptureInput>(c.capture_file, c.capture_rate);
  }
  throw std::invalid_argument("parameter 'input' = '" + c.input +
                              "': makeInput builds socket and capture; sim is built by "
                              "spinradar::sim::makeSimInput");
}

}  // namespace spinradar::navtech
