// libFuzzer target: arbitrary bytes, cut into arbitrary reads, through the whole decode chain
// (stream framer, message decoders, time decoding, scan assembly). Any crash, sanitizer report,
// hang or unbounded growth is a bug. Built with clang by test/driver.cmake.
#include <cstddef>
#include <cstdint>

#include "spinradar/driver/navtech_protocol.hpp"
#include "spinradar/driver/navtech_time.hpp"
#include "spinradar/driver/scan_assembler.hpp"

using namespace spinradar::navtech;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  // The first byte chooses the read size, so chunk boundaries are fuzzed too.
  const size_t chunk = 1 + data[0] % 97;
  const TimeByteOrder order = TimeByteOrder(data[1] % 3);
  data += 2;
  size -= 2;
  StreamParser parser(1u << 16);
  SensorTimeDecoder times(order);
  ClockMapper mapper;
  AssemblerOptions opt;
  opt.drop_partial = (size & 1) != 0;
  ScanAssembler assembler(opt);
  FftData fft;
  Configuration config;
  AssembledScan scan;
  int64_t rx = 0;
  for (size_t i = 0; i < size; i += chunk) {
    const size_t n = size - i < chunk ? size - i : chunk;
    parser.feed(data + i, n);
    rx += 1000;
    RawMessage m;
    while (parser.next(m)) {
      if (m.size > (1u << 16)) __builtin_trap();  // the limit must hold
      const auto type = MsgType(m.type);
      if (type == MsgType::Configuration && decodeConfiguration(m.payload, m.size, config)) {
        // Keep fuzzed rotations small so that one input stays fast.
        if (config.azimuth_samples <= 512)
          assembler.setConfiguration(config);
      } else if ((type == MsgType::FftData8 || type == MsgType::FftData16) &&
                 decodeFft(type, m.payload, m.size, fft)) {
        int64_t t = rx;
        if (times.decode(fft, t)) t = mapper.map(t, rx);
        if (assembler.add(fft, t, rx, scan)) {
          if (scan.scan.power.size() != size_t(scan.scan.azimuths) * scan.scan.bins) __builtin_trap();
        }
      }
    }
    if (parser.buffered() > (1u << 16) + 22 + chunk) __builtin_trap();  // bounded memory
  }
  return 0;
}
