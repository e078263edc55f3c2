// PNG files without OpenCV's imgcodecs (see include/spinradar/io/png_io.hpp).
#include "spinradar/io/png_io.hpp"

#include "spinradar/core/safe_output.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <spng.h>

#include "spinradar/io/png_gray8.hpp"

namespace spinradar {

namespace {

constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

struct SpngFree {
  void operator()(spng_ctx* c) const { spng_ctx_free(c); }
};
using SpngCtx = std::unique_ptr<spng_ctx, SpngFree>;

std::string unreadable(const std::string& path, const char* why) {
  return path + ": unreadable PNG (" + why + ")";
}

}  // namespace

cv::Mat readPngGray8(const std::string& path) {
  thread_local std::vector<uint8_t> bytes;
  thread_local PngGray8Decoder fast;  // exact, several times faster than libpng + zlib
  thread_local std::vector<uint8_t> slow;
  readFileBytes(path, bytes);
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0)
    throw std::runtime_error(path + ": not a PNG file (bad signature)");
  cv::Mat img;
  if (fast.decode(bytes.data(), bytes.size(), img)) return img;
  // Everything else through libspng: its header gives the reason for a refusal.
  SpngCtx ctx(spng_ctx_new(0));
  if (!ctx) throw std::bad_alloc();
  spng_ihdr h{};
  if (spng_set_png_buffer(ctx.get(), bytes.data(), bytes.size()) != 0 || spng_get_ihdr(ctx.get(), &h) != 0)
    throw std::runtime_error(unreadable(path, "corrupt or truncated header"));
  if (h.color_type != SPNG_COLOR_TYPE_GRAYSCALE || h.bit_depth > 8) {
    // Channels and depth as OpenCV's IMREAD_UNCHANGED would give them.
    const int channels = h.color_type == SPNG_COLOR_TYPE_GRAYSCALE ? 1
                         : (h.color_type == SPNG_COLOR_TYPE_TRUECOLOR || h.color_type == SPNG_COLOR_TYPE_INDEXED) ? 3
                                                                                                                 : 4;
    std::ostringstream s;
    s << path << ": " << channels << " channel(s) of " << (h.bit_depth == 16 ? 16 : 8)
      << "-bit, an 8-bit single-channel image expected";
    throw std::runtime_error(s.str());
  }
  size_t len = 0;
  const int e1 = spng_decoded_image_size(ctx.get(), SPNG_FMT_G8, &len);
  if (e1 != 0 || len != size_t(h.width) * h.height) throw std::runtime_error(unreadable(path, spng_strerror(e1)));
  // The header alone sets the size: refuse one no radar scan has before allocating for it.
  constexpr size_t kMaxImageBytes = size_t(1) << 30;
  if (len > kMaxImageBytes)
    throw std::runtime_error(path + ": the header says " + std::to_string(h.width) + " x " +
                             std::to_string(h.height) + " pixels, more than 1 GiB: not a radar scan");
  slow.resize(len);
  const int e2 = spng_decode_image(ctx.get(), slow.data(), len, SPNG_FMT_G8, 0);
  if (e2 != 0) throw std::runtime_error(unreadable(path, spng_strerror(e2)));
  return cv::Mat(static_cast<int>(h.height), static_cast<int>(h.width), CV_8UC1, slow.data());
}

void encodePng(const cv::Mat& image, std::vector<uint8_t>& png, int level) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw std::runtime_error("PNG encoding needs a non-empty 8-bit image of 1, 3 or 4 channels");
  const int ch = image.channels();
  // PNG stores RGB(A); OpenCV images are BGR(A).
  std::vector<uint8_t> rows(image.total() * ch);
  for (int r = 0; r < image.rows; ++r) {
    const uint8_t* src = image.ptr<uint8_t>(r);
    uint8_t* dst = rows.data() + size_t(r) * image.cols * ch;
    if (ch == 1) {
      std::memcpy(dst, src, image.cols);
      continue;
    }
    for (int c = 0; c < image.cols; ++c, src += ch, dst += ch) {
      dst[0] = src[2];
      dst[1] = src[1];
      dst[2] = src[0];
      if (ch == 4) dst[3] = src[3];
    }
  }
  SpngCtx ctx(spng_ctx_new(SPNG_CTX_ENCODER));
  if (!ctx) throw std::bad_alloc();
  spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1);
  spng_set_option(ctx.get(), SPNG_FILTER_CHOICE, SPNG_FILTER_CHOICE_SUB);
  spng_set_option(ctx.get(), SPNG_IMG_COMPRESSION_LEVEL, std::min(9, std::max(0, level)));
  spng_ihdr ihdr{};
  ihdr.width = static_cast<uint32_t>(image.cols);
  ihdr.height = static_cast<uint32_t>(image.rows);
  ihdr.bit_depth = 8;
  ihdr.color_type = ch == 1 ? SPNG_COLOR_TYPE_GRAYSCALE : ch == 3 ? SPNG_COLOR_TYPE_TRUECOLOR : SPNG_COLOR_TYPE_TRUECOLOR_ALPHA;
  int err = spng_set_ihdr(ctx.get(), &ihdr);
  if (err == 0) err = spng_encode_image(ctx.get(), rows.data(), rows.size(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  size_t len = 0;
  void* buf = err == 0 ? spng_get_png_buffer(ctx.get(), &len, &err) : nullptr;
  if (!buf) throw std::runtime_error(std::string("PNG encoding failed: ") + spng_strerror(err));
  png.assign(static_cast<uint8_t*>(buf), static_cast<uint8_t*>(buf) + len);
  std::free(buf);
}

void writePng(const cv::Mat& image, const std::string& path, int level) {
  std::vector<uint8_t> png;
  try {
    encodePng(image, png, level);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": cannot write PNG (" + e.what() + ")");
  }
  // The one temp-file-and-rename helper (core/safe_output.hpp): no half-written PNG is left.
  try {
    AtomicOutputFile file(path);
    file.stream().write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
    file.commit();
  } catch (const std::runtime_error& e) {
    std::string why = e.what();
    if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
    throw std::runtime_error(path + ": cannot write PNG (" + why + ")");
  }
}

}  // namespace spinradar
