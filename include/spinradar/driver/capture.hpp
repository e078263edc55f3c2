#pragma once
// Raw capture of the radar's TCP byte stream: every recv() chunk with its receive time, plus
// connect / disconnect marks, so a replay feeds the parser exactly what the live driver saw
// (same chunking, same receive stamps, same resets) and yields identical scans.
//
// File layout (little-endian): magic "SPINCAP1", then records
//   int64 receive_ns | uint32 kind_or_length | bytes
// where kind_or_length < 0xFFFFFFF0 is the length of a data chunk that follows, 0xFFFFFFFE a
// disconnect mark and 0xFFFFFFFD a connect mark (no bytes follow a mark).
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace spinradar::navtech {

class CaptureWriter {
 public:
  CaptureWriter() = default;
  explicit CaptureWriter(const std::string& path) { open(path); }
  ~CaptureWriter();
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  void open(const std::string& path);  ///< throws std::runtime_error naming the file
  bool isOpen() const { return f_ != nullptr; }
  void writeChunk(int64_t receive_ns, const uint8_t* data, size_t n);
  void writeConnect(int64_t receive_ns);
  void writeDisconnect(int64_t receive_ns);
  void close();

 private:
  void writeRecord(int64_t receive_ns, uint32_t kind, const uint8_t* data, size_t n);
  std::FILE* f_ = nullptr;
  std::string path_;
};

class CaptureReader {
 public:
  enum class Kind { Data, Connect, Disconnect, End };
  struct Record {
    Kind kind = Kind::End;
    int64_t receive_ns = 0;
    std::vector<uint8_t> data;  ///< reused
  };
  explicit CaptureReader(const std::string& path);  ///< throws naming the file
  ~CaptureReader();
  CaptureReader(const CaptureReader&) = delete;
  CaptureReader& operator=(const CaptureReader&) = delete;

  /// Next record; Kind::End at the end. A record cut short by the end of the file (a capture
  /// interrupted while writing) ends the replay; other corruption throws naming file and offset.
  bool next(Record& r);
  const std::string& path() const { return path_; }
  /// After next() returned false: byte offset of the record the file cut short, -1 when the
  /// file ended cleanly between records.
  int64_t truncatedAt() const { return truncated_at_; }

 private:
  std::FILE* f_ = nullptr;
  std::string path_;
  int64_t truncated_at_ = -1;
};

}  // namespace spinradar::navtech
