#pragma once
// The Navtech "Colossus" TCP protocol (docs: ../shared/navtech-protocol.md): encoder and
// decoder, written once. The driver decodes with it; the sensor emulator and the simulator's
// live mode encode with it. No ROS, no sockets: byte buffers only, so it is testable from
// hand-built buffers and fuzzable.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace spinradar::navtech {

constexpr std::array<uint8_t, 16> kSignature = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                                0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE};
constexpr size_t kHeaderSize = 22;
/// The version byte this project sends. Received messages are accepted whatever their version
/// byte: Navtech's own SDK examples send 0 and real radars answer them.
constexpr uint8_t kProtocolVersion = 1;
/// Payloads larger than this are refused (the largest real FFT message is ~14 KB).
constexpr uint32_t kMaxPayload = 1u << 20;
constexpr size_t kFftSubHeader = 14;
constexpr size_t kConfigurationSize = 20;  ///< fixed part; a protobuf tail may follow
constexpr int kDefaultPort = 6317;

enum class MsgType : uint8_t {
  KeepAlive = 1,
  Configuration = 10,
  ConfigurationRequest = 20,
  StartFftData = 21,
  StopFftData = 22,
  FftData8 = 30,
  FftData16 = 31,
};

/// Byte order of the FFT seconds / nanoseconds fields (sources disagree, see the docs).
enum class TimeByteOrder { Auto, Little, Big };
TimeByteOrder parseTimeByteOrder(const std::string& s);  ///< "auto" | "little" | "big"

/// Configuration message (type 10), the fixed 20-byte part.
struct Configuration {
  uint16_t azimuth_samples = 400;
  uint16_t bin_size = 438;       ///< 0.1 mm units
  uint16_t range_in_bins = 3768;
  uint16_t encoder_size = 5600;
  uint16_t rotation_mhz = 4000;  ///< rotation speed, mHz
  uint16_t packet_rate = 1600;   ///< azimuths per second
  float range_gain = 1.0f;
  float range_offset = 0.0f;     ///< m

  double rangeResolution() const { return bin_size * 1e-4; }
  double rotationHz() const { return rotation_mhz * 1e-3; }
  /// True when the figures can describe a real rotation (non-zero sizes, encoder >= azimuths).
  bool plausible() const;
  bool operator==(const Configuration& o) const;
  bool operator!=(const Configuration& o) const { return !(*this == o); }
};

/// FFT data message (type 30 or 31). `power` always holds the bins widened to uint16 so one
/// buffer serves both depths; `bit_depth` tells which message it came from.
struct FftData {
  uint16_t sweep_counter = 0;
  uint16_t encoder = 0;
  std::array<uint8_t, 4> seconds_raw{};      ///< as on the wire
  std::array<uint8_t, 4> nanoseconds_raw{};  ///< as on the wire
  int bit_depth = 8;
  std::vector<uint16_t> power;  ///< reused across messages: no allocation after warm-up

  uint32_t seconds(bool big_endian) const;
  uint32_t nanoseconds(bool big_endian) const;
};

// ---- decoding ----
uint16_t readU16BE(const uint8_t* p);
uint32_t readU32BE(const uint8_t* p);
uint32_t readU32LE(const uint8_t* p);

/// Parses a 22-byte header. Returns false when the signature is wrong; any version byte is
/// accepted (written to `version` when given).
bool decodeHeader(const uint8_t* p, uint8_t& type, uint32_t& payload_size,
                  uint8_t* version = nullptr);
/// Returns false when the payload is shorter than 20 bytes.
bool decodeConfiguration(const uint8_t* payload, size_t size, Configuration& out);
/// Returns false when the payload is malformed (too short, data offset outside the payload,
/// odd byte count for 16-bit bins).
bool decodeFft(MsgType type, const uint8_t* payload, size_t size, FftData& out);

// ---- encoding (appends to `out`) ----
void encodeHeader(std::vector<uint8_t>& out, MsgType type, uint32_t payload_size);
void encodeEmpty(std::vector<uint8_t>& out, MsgType type);  ///< keep-alive, start, stop, request
void encodeConfiguration(std::vector<uint8_t>& out, const Configuration& c);
/// 8-bit FFT message. stamp_ns is split into seconds and nanoseconds written in `order`
/// (Auto means Little, which is what real sensors send as the SDK's readers show).
void encodeFft8(std::vector<uint8_t>& out, uint16_t sweep, uint16_t encoder, int64_t stamp_ns,
                const uint8_t* bins, size_t n, TimeByteOrder order = TimeByteOrder::Little);
/// 16-bit FFT message, bins big-endian.
void encodeFft16(std::vector<uint8_t>& out, uint16_t sweep, uint16_t encoder, int64_t stamp_ns,
                 const uint16_t* bins, size_t n, TimeByteOrder order = TimeByteOrder::Little);

/// One framed message as returned by StreamParser::next(). `payload` points into the parser's
/// buffer and stays valid until the next call to feed() or next().
struct RawMessage {
  uint8_t type = 0;
  uint8_t version = 0;  ///< the header's protocol version byte, as sent
  const uint8_t* payload = nullptr;
  uint32_t size = 0;
};

/// Counters of what the parser had to throw away (never reset except by reset()).
struct StreamStats {
  uint64_t messages = 0;          ///< complete, well-framed messages returned
  uint64_t garbage_bytes = 0;     ///< bytes skipped while looking for a signature
  uint64_t resyncs = 0;           ///< times the parser had to search for a signature
  uint64_t oversized = 0;         ///< headers refused for a payload over the limit
  uint64_t truncated = 0;         ///< messages cut short by a new signature inside the payload
};

/// Incremental framer for the TCP byte stream: feed() whatever recv() returned, then call
/// next() until it returns false. Resynchronises on the signature after garbage, refuses
/// payloads over `max_payload`, keeps partial messages across reads, and detects a message cut
/// short by the sender (a signature + valid header inside its payload) so that the bytes of
/// the next message are never decoded as part of the previous one. Memory is bounded by
/// max_payload + one read.
class StreamParser {
 public:
  explicit StreamParser(uint32_t max_payload = kMaxPayload) : max_payload_(max_payload) {}
  void feed(const uint8_t* data, size_t n);
  bool next(RawMessage& out);
  void reset();  ///< drop buffered bytes (e.g. on reconnect); keeps the counters
  const StreamStats& stats() const { return stats_; }
  size_t buffered() const { return buf_.size() - pos_; }

 private:
  void skip(size_t n, bool garbage);
  size_t findSignature(size_t from, size_t to) const;
  bool tailLooksLikeSignature(size_t end) const;  ///< absolute index or buf_.size()

  uint32_t max_payload_;
  std::vector<uint8_t> buf_;
  size_t pos_ = 0;
  bool in_sync_ = true;
  StreamStats stats_;
};

}  // namespace spinradar::navtech
