// Byte-level tests of the Navtech protocol decoder from hand-built buffers.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "spinradar/driver/navtech_protocol.hpp"
#include "spinradar/driver/navtech_time.hpp"

using namespace spinradar::navtech;

namespace {

std::vector<uint8_t> header(uint8_t type, uint32_t size) {
  std::vector<uint8_t> b = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                            0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE, 0x01, type};
  b.push_back(uint8_t(size >> 24));
  b.push_back(uint8_t(size >> 16));
  b.push_back(uint8_t(size >> 8));
  b.push_back(uint8_t(size));
  return b;
}

// FFT message by hand: seconds 1600000000 (0x5F5E1000), nanoseconds 250000000 (0x0EE6B280).
std::vector<uint8_t> handFft8(bool time_big_endian, std::vector<uint8_t> bins) {
  auto b = header(30, uint32_t(14 + bins.size()));
  const uint8_t sub_be[] = {0x00, 0x0E, 0x12, 0x34, 0x05, 0x78};  // offset 14, sweep, enc 1400
  b.insert(b.end(), sub_be, sub_be + 6);
  const uint8_t sec_be[] = {0x5F, 0x5E, 0x10, 0x00}, ns_be[] = {0x0E, 0xE6, 0xB2, 0x80};
  for (int i = 0; i < 4; ++i) b.push_back(time_big_endian ? sec_be[i] : sec_be[3 - i]);
  for (int i = 0; i < 4; ++i) b.push_back(time_big_endian ? ns_be[i] : ns_be[3 - i]);
  b.insert(b.end(), bins.begin(), bins.end());
  return b;
}

std::vector<RawMessage> parseAll(StreamParser& p, const std::vector<uint8_t>& bytes,
                                 size_t chunk = 1 << 20) {
  std::vector<RawMessage> out;
  for (size_t i = 0; i < bytes.size(); i += chunk) {
    p.feed(bytes.data() + i, std::min(chunk, bytes.size() - i));
    RawMessage m;
    while (p.next(m)) out.push_back(m);
  }
  return out;
}

}  // namespace

TEST(NavtechProtocol, HeaderFromHandBuiltBytes) {
  auto b = header(31, 0x00010203);
  uint8_t type;
  uint32_t size;
  ASSERT_TRUE(decodeHeader(b.data(), type, size));
  EXPECT_EQ(type, 31);
  EXPECT_EQ(size, 0x00010203u);  // big-endian
  b[16] = 2;                      // any version byte is accepted and reported
  uint8_t version = 99;
  EXPECT_TRUE(decodeHeader(b.data(), type, size, &version));
  EXPECT_EQ(version, 2);
  b[3] = 0x04;  // wrong signature
  EXPECT_FALSE(decodeHeader(b.data(), type, size));
}

TEST(NavtechProtocol, ConfigurationFromHandBuiltBytes) {
  // 400 azimuths, 438 (0.0438 m), 3768 bins, encoder 5600, 4000 mHz, 1600/s, gain 1.0, offset -0.31
  const uint8_t p[] = {0x01, 0x90, 0x01, 0xB6, 0x0E, 0xB8, 0x15, 0xE0, 0x0F, 0xA0,
                       0x06, 0x40, 0x3F, 0x80, 0x00, 0x00, 0xBE, 0x9E, 0xB8, 0x52};
  Configuration c;
  ASSERT_TRUE(decodeConfiguration(p, sizeof p, c));
  EXPECT_EQ(c.azimuth_samples, 400);
  EXPECT_NEAR(c.rangeResolution(), 0.0438, 1e-12);
  EXPECT_EQ(c.range_in_bins, 3768);
  EXPECT_EQ(c.encoder_size, 5600);
  EXPECT_DOUBLE_EQ(c.rotationHz(), 4.0);
  EXPECT_EQ(c.packet_rate, 1600);
  EXPECT_FLOAT_EQ(c.range_gain, 1.0f);
  EXPECT_FLOAT_EQ(c.range_offset, -0.31f);
  EXPECT_FALSE(decodeConfiguration(p, 19, c));
  // Encoder round trip, with the optional tail ignored.
  std::vector<uint8_t> enc;
  encodeConfiguration(enc, c);
  ASSERT_EQ(enc.size(), kHeaderSize + 20);
  EXPECT_EQ(0, std::memcmp(enc.data() + kHeaderSize, p, 20));
}

TEST(NavtechProtocol, Fft8BothTimeByteOrders) {
  for (bool big : {false, true}) {
    const auto b = handFft8(big, {0, 7, 255});
    FftData f;
    ASSERT_TRUE(decodeFft(MsgType::FftData8, b.data() + kHeaderSize, b.size() - kHeaderSize, f));
    EXPECT_EQ(f.sweep_counter, 0x1234);
    EXPECT_EQ(f.encoder, 1400);
    EXPECT_EQ(f.bit_depth, 8);
    ASSERT_EQ(f.power.size(), 3u);
    EXPECT_EQ(f.power[1], 7);
    EXPECT_EQ(f.power[2], 255);
    EXPECT_EQ(f.seconds(big), 1600000000u);
    EXPECT_EQ(f.nanoseconds(big), 250000000u);
    // Forced order and auto detection both give the true time.
    int64_t t = 0;
    SensorTimeDecoder forced(big ? TimeByteOrder::Big : TimeByteOrder::Little);
    ASSERT_TRUE(forced.decode(f, t));
    EXPECT_EQ(t, 1600000000250000000);
    SensorTimeDecoder autod(TimeByteOrder::Auto);
    ASSERT_TRUE(autod.decode(f, t));
    EXPECT_EQ(t, 1600000000250000000);
    // The wrong forced order reads nanoseconds >= 1e9: refused, stamp untouched.
    SensorTimeDecoder wrong(big ? TimeByteOrder::Little : TimeByteOrder::Big);
    t = -1;
    EXPECT_FALSE(wrong.decode(f, t));
    EXPECT_EQ(t, -1);
  }
}

TEST(NavtechProtocol, AutoByteOrderLearnsSmallSimulatorClock) {
  // Seconds near zero (a simulator clock): one message alone is ambiguous, a few settle it.
  for (auto order : {TimeByteOrder::Little, TimeByteOrder::Big}) {
    SensorTimeDecoder d(TimeByteOrder::Auto);
    std::vector<uint8_t> buf;
    const uint8_t bins[4] = {1, 2, 3, 4};
    int64_t t = 0;
    for (int i = 0; i < 40; ++i) {
      buf.clear();
      const int64_t stamp = 12'000'000'000 + int64_t(i) * 625'000;
      encodeFft8(buf, 0, uint16_t(i * 14), stamp, bins, 4, order);
      FftData f;
      ASSERT_TRUE(decodeFft(MsgType::FftData8, buf.data() + kHeaderSize, buf.size() - kHeaderSize, f));
      const bool ok = d.decode(f, t);
      if (i >= 8) {
        ASSERT_TRUE(ok);
        EXPECT_EQ(t, stamp) << "message " << i;
      }
    }
    EXPECT_EQ(d.current(), order);
  }
}

TEST(NavtechProtocol, Fft16BigEndianBins) {
  auto b = header(31, 14 + 6);
  const uint8_t sub[] = {0x00, 0x0E, 0x00, 0x01, 0x15, 0xDF, 0, 0, 0, 0, 0, 0, 0, 0,
                         0x12, 0x34, 0xFF, 0x00, 0x00, 0x01};
  b.insert(b.end(), sub, sub + sizeof sub);
  FftData f;
  ASSERT_TRUE(decodeFft(MsgType::FftData16, b.data() + kHeaderSize, 20, f));
  EXPECT_EQ(f.bit_depth, 16);
  EXPECT_EQ(f.encoder, 5599);
  ASSERT_EQ(f.power.size(), 3u);
  EXPECT_EQ(f.power[0], 0x1234);
  EXPECT_EQ(f.power[1], 0xFF00);
  EXPECT_EQ(f.power[2], 0x0001);
  EXPECT_FALSE(decodeFft(MsgType::FftData16, b.data() + kHeaderSize, 19, f));  // odd bin bytes
  // Encoder writes the same bytes.
  std::vector<uint8_t> enc;
  const uint16_t bins[] = {0x1234, 0xFF00, 0x0001};
  encodeFft16(enc, 1, 5599, 0, bins, 3);
  EXPECT_EQ(enc, b);
}

TEST(NavtechProtocol, MalformedFftRefused) {
  FftData f;
  const uint8_t short_payload[10] = {};
  EXPECT_FALSE(decodeFft(MsgType::FftData8, short_payload, sizeof short_payload, f));
  uint8_t bad_offset[20] = {0x00, 0x40};  // data offset 64 > payload size
  EXPECT_FALSE(decodeFft(MsgType::FftData8, bad_offset, sizeof bad_offset, f));
  uint8_t small_offset[20] = {0x00, 0x02};  // data offset inside the sub-header
  EXPECT_FALSE(decodeFft(MsgType::FftData8, small_offset, sizeof small_offset, f));
  EXPECT_FALSE(decodeFft(MsgType::KeepAlive, short_payload, sizeof short_payload, f));
}

TEST(NavtechProtocol, ParserSkipsUnknownTypesAndKeepsOrder) {
  std::vector<uint8_t> s;
  encodeEmpty(s, MsgType::KeepAlive);
  auto unknown = header(40, 5);  // health message, payload to skip
  unknown.insert(unknown.end(), {9, 9, 9, 9, 9});
  s.insert(s.end(), unknown.begin(), unknown.end());
  const auto fft = handFft8(false, {1, 2, 3});
  s.insert(s.end(), fft.begin(), fft.end());
  StreamParser p;
  auto msgs = parseAll(p, s);
  ASSERT_EQ(msgs.size(), 3u);
  EXPECT_EQ(msgs[0].type, 1);
  EXPECT_EQ(msgs[1].type, 40);
  EXPECT_EQ(msgs[1].size, 5u);
  EXPECT_EQ(msgs[2].type, 30);
  EXPECT_EQ(p.stats().garbage_bytes, 0u);
}

TEST(NavtechProtocol, ParserHandlesEveryChunking) {
  std::vector<uint8_t> s;
  for (int i = 0; i < 5; ++i) {
    const auto fft = handFft8(false, {uint8_t(i), 2, 3, 4});
    s.insert(s.end(), fft.begin(), fft.end());
  }
  for (size_t chunk : {1u, 2u, 7u, 21u, 22u, 23u, 39u, 1000u}) {
    StreamParser p;
    std::vector<uint8_t> firsts;
    for (size_t i = 0; i < s.size(); i += chunk) {
      p.feed(s.data() + i, std::min(chunk, s.size() - i));
      RawMessage m;
      while (p.next(m)) firsts.push_back(m.payload[14]);
    }
    EXPECT_EQ(firsts, (std::vector<uint8_t>{0, 1, 2, 3, 4})) << "chunk " << chunk;
    EXPECT_EQ(p.stats().garbage_bytes, 0u);
    EXPECT_EQ(p.buffered(), 0u);
  }
}

TEST(NavtechProtocol, ParserResynchronisesAfterGarbage) {
  std::vector<uint8_t> s = {0xDE, 0xAD, 0x00, 0x01, 0x03, 0x03, 0x07};  // incl. a false start
  const auto fft = handFft8(false, {42});
  s.insert(s.end(), fft.begin(), fft.end());
  for (int i = 0; i < 300; ++i) s.push_back(uint8_t(i * 37));
  s.insert(s.end(), fft.begin(), fft.end());
  for (size_t chunk : {1u, 5u, 64u, 4096u}) {
    StreamParser p;
    auto msgs = parseAll(p, s, chunk);
    ASSERT_EQ(msgs.size(), 2u) << "chunk " << chunk;
    EXPECT_EQ(p.stats().garbage_bytes, 7u + 300u);
    EXPECT_EQ(p.stats().resyncs, 2u);
  }
}

TEST(NavtechProtocol, ParserRefusesOversizedPayload) {
  auto s = header(30, 50u << 20);  // 50 MB announced, nothing follows
  const auto fft = handFft8(false, {42});
  s.insert(s.end(), fft.begin(), fft.end());
  StreamParser p;
  auto msgs = parseAll(p, s);
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_EQ(msgs[0].type, 30);
  EXPECT_EQ(p.stats().oversized, 1u);
  EXPECT_EQ(p.buffered(), 0u);  // nothing held back waiting for 50 MB
}

TEST(NavtechProtocol, ParserDropsMessageCutShortBySender) {
  const auto fft = handFft8(false, {1, 2, 3, 4, 5, 6, 7, 8});
  std::vector<uint8_t> s(fft.begin(), fft.begin() + 30);  // truncated: 30 of 44 bytes
  for (int i = 0; i < 3; ++i) s.insert(s.end(), fft.begin(), fft.end());
  StreamParser p;
  auto msgs = parseAll(p, s, 13);
  ASSERT_EQ(msgs.size(), 3u);  // the cut one is dropped, the three complete ones survive
  for (auto& m : msgs) EXPECT_EQ(m.size, 22u);
  EXPECT_EQ(p.stats().truncated, 1u);
}

TEST(NavtechProtocol, ParserWaitsForTruncatedTailAcrossReads) {
  const auto fft = handFft8(true, {5, 6});
  StreamParser p;
  p.feed(fft.data(), 25);
  RawMessage m;
  EXPECT_FALSE(p.next(m));
  EXPECT_EQ(p.buffered(), 25u);
  p.feed(fft.data() + 25, fft.size() - 25);
  ASSERT_TRUE(p.next(m));
  EXPECT_EQ(m.size, 16u);
  EXPECT_EQ(m.payload[15], 6);
}

TEST(NavtechProtocol, StartFftDataWithVersionZeroAccepted) {
  // The exact Start FFT Data message of Navtech's SDK example ReadOneRotationOfFFTData.py:
  // protocol version byte 0 (its `version` variable is never set). Real radars answer it.
  const std::vector<uint8_t> start = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                      0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE,
                                      0x00, 0x15, 0x00, 0x00, 0x00, 0x00};
  StreamParser p;
  for (size_t chunk : {size_t(1), size_t(7), size_t(64)}) {
    auto msgs = parseAll(p, start, chunk);
    ASSERT_EQ(msgs.size(), 1u) << "chunk " << chunk;
    EXPECT_EQ(msgs[0].type, uint8_t(MsgType::StartFftData));
    EXPECT_EQ(msgs[0].version, 0);
    EXPECT_EQ(msgs[0].size, 0u);
  }
  EXPECT_EQ(p.stats().garbage_bytes, 0u);
}

TEST(NavtechProtocol, FftDataWithAnyVersionDecoded) {
  for (uint8_t version : {uint8_t(0), uint8_t(1), uint8_t(2), uint8_t(255)}) {
    auto b = handFft8(false, {42, 43});
    b[16] = version;
    StreamParser p;
    auto msgs = parseAll(p, b);
    ASSERT_EQ(msgs.size(), 1u) << int(version);
    EXPECT_EQ(msgs[0].version, version);
    FftData d;
    ASSERT_TRUE(decodeFft(MsgType(msgs[0].type), msgs[0].payload, msgs[0].size, d));
    EXPECT_EQ(d.encoder, 1400);
    EXPECT_EQ(d.power, (std::vector<uint16_t>{42, 43}));
  }
}

TEST(NavtechProtocol, GarbageMemoryStaysBounded) {
  StreamParser p;
  std::vector<uint8_t> junk(100000, 0xAB);
  RawMessage m;
  for (int i = 0; i < 100; ++i) {
    p.feed(junk.data(), junk.size());
    while (p.next(m)) {
    }
    EXPECT_LT(p.buffered(), kSignature.size());
  }
}
