#pragma once
// Fast decoding of the 8-bit grayscale PNGs that hold Oxford / Boreas polar scans.
//
// OpenCV's decoder (libpng + zlib) was most of the whole-process time on recorded drives. The
// fast path parses the chunks itself, inflates all image data in one call of libdeflate and
// undoes the row filters once, in place (Sub, the filter OpenCV and the Oxford files use, with
// SSE prefix sums). Every row and column is needed (metadata and bins up to the last one reach
// the Cartesian image), so nothing is skipped. Anything it does not handle byte for byte as
// OpenCV (colour, 16-bit, palette, interlace, tRNS, unknown or damaged chunks, CRC or Adler
// mismatches, short or long data) is refused, so that what it returns is always OpenCV's.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace spinradar {

enum class PngDecoder {
  Deflate,  ///< own chunk parser + libdeflate + one in-place unfilter pass (fastest, default)
  Spng,     ///< libspng (zlib inflate inside)
};
const char* pngDecoderName(PngDecoder decoder);

/// Reads a whole file into `bytes` (reusing its capacity). Throws std::runtime_error naming the
/// file when it cannot be opened or read.
void readFileBytes(const std::string& path, std::vector<uint8_t>& bytes);

/// Holds the decoder state and buffers so that repeated decodes of same-sized images do not
/// allocate. Not thread-safe: one per thread.
class PngGray8Decoder {
 public:
  explicit PngGray8Decoder(PngDecoder method = PngDecoder::Deflate);
  ~PngGray8Decoder();
  PngGray8Decoder(const PngGray8Decoder&) = delete;
  PngGray8Decoder& operator=(const PngGray8Decoder&) = delete;

  /// Decodes an 8-bit grayscale, non-interlaced PNG held in memory. On success `image` is a
  /// CV_8UC1 header over this decoder's buffer, valid until the next call (copy it to keep it).
  /// Returns false, leaving `image` empty, when this PNG is one the method does not handle
  /// exactly as OpenCV (see the file comment): readPngGray8 (png_io.hpp) then uses libspng.
  bool decode(const uint8_t* png, size_t size, cv::Mat& image);

 private:
  bool decodeDeflate(const uint8_t* png, size_t size, cv::Mat& image);
  bool decodeSpng(const uint8_t* png, size_t size, cv::Mat& image);

  PngDecoder method_;
  struct Inflater;
  std::unique_ptr<Inflater> inflater_;
  std::vector<uint8_t> idat_;    ///< concatenated compressed image data
  std::vector<uint8_t> pixels_;  ///< height x (1 filter byte + width)
};

}  // namespace spinradar
