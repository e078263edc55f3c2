#include "spinradar/driver/navtech_protocol.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace spinradar::navtech {

TimeByteOrder parseTimeByteOrder(const std::string& s) {
  if (s == "auto") return TimeByteOrder::Auto;
  if (s == "little") return TimeByteOrder::Little;
  if (s == "big") return TimeByteOrder::Big;
  throw std::invalid_argument("parameter 'time_byte_order' = '" + s +
                              "' is not one of: auto, little, big");
}

bool Configuration::plausible() const {
  return azimuth_samples > 0 && bin_size > 0 && range_in_bins > 0 && encoder_size > 0 &&
         encoder_size >= azimuth_samples;
}

bool Configuration::operator==(const Configuration& o) const {
  return azimuth_samples == o.azimuth_samples && bin_size == o.bin_size &&
         range_in_bins == o.range_in_bins && encoder_size == o.encoder_size &&
         rotation_mhz == o.rotation_mhz && packet_rate == o.packet_rate &&
         range_gain == o.range_gain && range_offset == o.range_offset;
}

uint16_t readU16BE(const uint8_t* p) { return uint16_t((p[0] << 8) | p[1]); }
uint32_t readU32BE(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}
uint32_t readU32LE(const uint8_t* p) {
  return (uint32_t(p[3]) << 24) | (uint32_t(p[2]) << 16) | (uint32_t(p[1]) << 8) | p[0];
}

uint32_t FftData::seconds(bool big_endian) const {
  return big_endian ? readU32BE(seconds_raw.data()) : readU32LE(seconds_raw.data());
}
uint32_t FftData::nanoseconds(bool big_endian) const {
  return big_endian ? readU32BE(nanoseconds_raw.data()) : readU32LE(nanoseconds_raw.data());
}

namespace {

float floatFromBits(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
uint32_t bitsFromFloat(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}
void putU16BE(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(uint8_t(v >> 8));
  out.push_back(uint8_t(v));
}
void putU32BE(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}
void putU32(std::vector<uint8_t>& out, uint32_t v, TimeByteOrder order) {
  if (order == TimeByteOrder::Big) {
    putU32BE(out, v);
  } else {
    for (int s = 0; s <= 24; s += 8) out.push_back(uint8_t(v >> s));
  }
}

void encodeFftHead(std::vector<uint8_t>& out, MsgType type, size_t bin_bytes, uint16_t sweep,
                   uint16_t encoder, int64_t stamp_ns, TimeByteOrder order) {
  encodeHeader(out, type, uint32_t(kFftSubHeader + bin_bytes));
  putU16BE(out, uint16_t(kFftSubHeader));
  putU16BE(out, sweep);
  putU16BE(out, encoder);
  const int64_t t = stamp_ns < 0 ? 0 : stamp_ns;
  putU32(out, uint32_t(t / 1000000000), order);
  putU32(out, uint32_t(t % 1000000000), order);
}

}  // namespace

bool decodeHeader(const uint8_t* p, uint8_t& type, uint32_t& payload_size, uint8_t* version) {
  if (std::memcmp(p, kSignature.data(), kSignature.size()) != 0) return false;
  if (version) *version = p[16];
  type = p[17];
  payload_size = readU32BE(p + 18);
  return true;
}

bool decodeConfiguration(const uint8_t* p, size_t size, Configuration& c) {
  if (size < kConfigurationSize) return false;
  c.azimuth_samples = readU16BE(p);
  c.bin_size = readU16BE(p + 2);
  c.range_in_bins = readU16BE(p + 4);
  c.encoder_size = readU16BE(p + 6);
  c.rotation_mhz = readU16BE(p + 8);
  c.packet_rate = readU16BE(p + 10);
  c.range_gain = floatFromBits(readU32BE(p + 12));
  c.range_offset = floatFromBits(readU32BE(p + 16));
  return true;
}

bool decodeFft(MsgType type, const uint8_t* p, size_t size, FftData& out) {
  if (size < kFftSubHeader) return false;
  const size_t offset = readU16BE(p);
  if (offset < kFftSubHeader || offset >= size) return false;
  out.sweep_counter = readU16BE(p + 2);
  out.encoder = readU16BE(p + 4);
  std::memcpy(out.seconds_raw.data(), p + 6, 4);
  std::memcpy(out.nanoseconds_raw.data(), p + 10, 4);
  const uint8_t* bins = p + offset;
  const size_t n = size - offset;
  if (type == MsgType::FftData8) {
    out.bit_depth = 8;
    out.power.resize(n);
    for (size_t i = 0; i < n; ++i) out.power[i] = bins[i];
    return true;
  }
  if (type == MsgType::FftData16) {
    if (n % 2 != 0) return false;
    out.bit_depth = 16;
    out.power.resize(n / 2);
    for (size_t i = 0; i < n / 2; ++i) out.power[i] = readU16BE(bins + 2 * i);
    return true;
  }
  return false;
}

void encodeHeader(std::vector<uint8_t>& out, MsgType type, uint32_t payload_size) {
  out.insert(out.end(), kSignature.begin(), kSignature.end());
  out.push_back(kProtocolVersion);
  out.push_back(uint8_t(type));
  putU32BE(out, payload_size);
}

void encodeEmpty(std::vector<uint8_t>& out, MsgType type) { encodeHeader(out, type, 0); }

void encodeConfiguration(std::vector<uint8_t>& out, const Configuration& c) {
  encodeHeader(out, MsgType::Configuration, uint32_t(kConfigurationSize));
  putU16BE(out, c.azimuth_samples);
  putU16BE(out, c.bin_size);
  putU16BE(out, c.range_in_bins);
  putU16BE(out, c.encoder_size);
  putU16BE(out, c.rotation_mhz);
  putU16BE(out, c.packet_rate);
  putU32BE(out, bitsFromFloat(c.range_gain));
  putU32BE(out, bitsFromFloat(c.range_offset));
}

void encodeFft8(std::vector<uint8_t>& out, uint16_t sweep, uint16_t encoder, int64_t stamp_ns,
                const uint8_t* bins, size_t n, TimeByteOrder order) {
  encodeFftHead(out, MsgType::FftData8, n, sweep, encoder, stamp_ns, order);
  out.insert(out.end(), bins, bins + n);
}

void encodeFft16(std::vector<uint8_t>& out, uint16_t sweep, uint16_t encoder, int64_t stamp_ns,
                 const uint16_t* bins, size_t n, TimeByteOrder order) {
  encodeFftHead(out, MsgType::FftData16, 2 * n, sweep, encoder, stamp_ns, order);
  for (size_t i = 0; i < n; ++i) putU16BE(out, bins[i]);
}

// ---- StreamParser ----

void StreamParser::feed(const uint8_t* data, size_t n) {
  // Compact before growing so the buffer stays bounded by one message plus one read.
  if (pos_ > 0 && (pos_ == buf_.size() || pos_ > 65536 || pos_ * 2 > buf_.size())) {
    buf_.erase(buf_.begin(), buf_.begin() + long(pos_));
    pos_ = 0;
  }
  buf_.insert(buf_.end(), data, data + n);
}

void StreamParser::reset() {
  buf_.clear();
  pos_ = 0;
  in_sync_ = true;
}

void StreamParser::skip(size_t n, bool garbage) {
  if (garbage) {
    if (in_sync_) ++stats_.resyncs;
    in_sync_ = false;
    stats_.garbage_bytes += n;
  }
  pos_ += n;
}

size_t StreamParser::findSignature(size_t from, size_t to) const {
  if (to > buf_.size()) to = buf_.size();
  if (from >= to) return buf_.size();
  const void* hit = memmem(buf_.data() + from, to - from, kSignature.data(), kSignature.size());
  return hit ? size_t(static_cast<const uint8_t*>(hit) - buf_.data()) : buf_.size();
}

bool StreamParser::tailLooksLikeSignature(size_t end) const {
  // A signature prefix of at least 4 bytes that starts inside the payload and runs to the end
  // of the buffered bytes (shorter prefixes are too common in radar data to wait for).
  const size_t first = end >= kSignature.size() - 1 ? end - (kSignature.size() - 1) : 0;
  for (size_t s = std::max(first, pos_ + kHeaderSize); s < end; ++s) {
    const size_t len = buf_.size() - s;
    if (len >= 4 && len < kSignature.size() &&
        std::memcmp(buf_.data() + s, kSignature.data(), len) == 0)
      return true;
  }
  return false;
}

bool StreamParser::next(RawMessage& out) {
  for (;;) {
    const size_t avail = buf_.size() - pos_;
    const uint8_t* p = buf_.data() + pos_;
    const size_t cmp = avail < kSignature.size() ? avail : kSignature.size();
    // cmp == 0 on an empty buffer, where p may be null (memcmp's arguments must not be).
    if (cmp != 0 && std::memcmp(p, kSignature.data(), cmp) != 0) {
      const size_t s = findSignature(pos_ + 1, buf_.size());
      if (s == buf_.size()) {
        // Keep a tail that may be the start of a signature split across reads.
        const size_t keep = avail < kSignature.size() - 1 ? avail : kSignature.size() - 1;
        size_t drop = avail - keep;
        // The kept tail must itself be a signature prefix, else drop it too.
        while (drop < avail &&
               std::memcmp(buf_.data() + pos_ + drop, kSignature.data(), avail - drop) != 0)
          ++drop;
        skip(drop, true);
        return false;
      }
      skip(s - pos_, true);
      continue;
    }
    if (avail < kHeaderSize) return false;
    uint8_t type, version;
    uint32_t size;
    decodeHeader(p, type, size, &version);  // the signature was checked above
    if (size > max_payload_) {
      ++stats_.oversized;
      skip(1, true);
      continue;
    }
    if (avail < kHeaderSize + size) return false;
    // A sender that died mid-message and restarted leaves the next header inside this payload
    // (possibly straddling its end, hence the search 15 bytes past it).
    const size_t end = pos_ + kHeaderSize + size;
    const size_t inner = findSignature(pos_ + kHeaderSize, end + kSignature.size() - 1);
    if (inner < end) {
      ++stats_.truncated;
      skip(inner - pos_, true);
      continue;
    }
    if (inner == buf_.size() && end + kSignature.size() - 1 > buf_.size() && tailLooksLikeSignature(end))
      return false;  // a signature may be arriving across the payload's end: decide on more bytes
    out.type = type;
    out.version = version;
    out.payload = p + kHeaderSize;
    out.size = size;
    pos_ += kHeaderSize + size;
    in_sync_ = true;
    ++stats_.messages;
    return true;
  }
}

}  // namespace spinradar::navtech
