#include "spinradar/driver/capture.hpp"

#include <cstring>
#include <stdexcept>

namespace spinradar::navtech {

namespace {
constexpr char kMagic[8] = {'S', 'P', 'I', 'N', 'C', 'A', 'P', '1'};
constexpr uint32_t kConnect = 0xFFFFFFFDu;
constexpr uint32_t kDisconnect = 0xFFFFFFFEu;
constexpr uint32_t kMaxChunk = 64u << 20;

void putLE(uint8_t* p, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) p[i] = uint8_t(v >> (8 * i));
}
uint64_t getLE(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
}  // namespace

CaptureWriter::~CaptureWriter() { close(); }

void CaptureWriter::open(const std::string& path) {
  close();
  path_ = path;
  f_ = std::fopen(path.c_str(), "wb");
  if (!f_) throw std::runtime_error(path + ": cannot open capture file for writing: " +
                                    std::strerror(errno));
  if (std::fwrite(kMagic, 1, sizeof kMagic, f_) != sizeof kMagic)
    throw std::runtime_error(path + ": cannot write capture header");
}

void CaptureWriter::writeRecord(int64_t receive_ns, uint32_t kind, const uint8_t* data,
                                size_t n) {
  if (!f_) return;
  uint8_t head[12];
  putLE(head, uint64_t(receive_ns), 8);
  putLE(head + 8, kind, 4);
  if (std::fwrite(head, 1, sizeof head, f_) != sizeof head ||
      (n && std::fwrite(data, 1, n, f_) != n))
    throw std::runtime_error(path_ + ": cannot write capture record (disk full?)");
}

void CaptureWriter::writeChunk(int64_t receive_ns, const uint8_t* data, size_t n) {
  if (n) writeRecord(receive_ns, uint32_t(n), data, n);
}
void CaptureWriter::writeConnect(int64_t receive_ns) { writeRecord(receive_ns, kConnect, nullptr, 0); }
void CaptureWriter::writeDisconnect(int64_t receive_ns) {
  writeRecord(receive_ns, kDisconnect, nullptr, 0);
}

void CaptureWriter::close() {
  if (f_) std::fclose(f_);
  f_ = nullptr;
}

CaptureReader::CaptureReader(const std::string& path) : path_(path) {
  f_ = std::fopen(path.c_str(), "rb");
  if (!f_) throw std::runtime_error(path + ": cannot open capture file: " + std::strerror(errno));
  char magic[8];
  if (std::fread(magic, 1, 8, f_) != 8 || std::memcmp(magic, kMagic, 8) != 0) {
    std::fclose(f_);
    f_ = nullptr;
    throw std::runtime_error(path + ": not a spinradar capture file (bad magic)");
  }
}

CaptureReader::~CaptureReader() {
  if (f_) std::fclose(f_);
}

bool CaptureReader::next(Record& r) {
  r.kind = Kind::End;
  r.data.clear();
  if (!f_) return false;
  const long offset = std::ftell(f_);
  uint8_t head[12];
  const size_t got = std::fread(head, 1, sizeof head, f_);
  if (got != sizeof head) {
    if (got > 0) truncated_at_ = offset;
    return false;
  }
  r.receive_ns = int64_t(getLE(head, 8));
  const uint32_t kind = uint32_t(getLE(head + 8, 4));
  if (kind == kConnect) {
    r.kind = Kind::Connect;
    return true;
  }
  if (kind == kDisconnect) {
    r.kind = Kind::Disconnect;
    return true;
  }
  if (kind > kMaxChunk)
    throw std::runtime_error(path_ + ": corrupt capture record at byte " + std::to_string(offset) +
                             " (length " + std::to_string(kind) + ")");
  r.data.resize(kind);
  if (std::fread(r.data.data(), 1, kind, f_) != kind) {
    r.data.clear();
    truncated_at_ = offset;
    return false;  // interrupted recording: end of replay
  }
  r.kind = Kind::Data;
  return true;
}

}  // namespace spinradar::navtech
