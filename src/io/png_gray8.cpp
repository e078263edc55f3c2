// Fast 8-bit grayscale PNG decoding (see include/spinradar/io/png_gray8.hpp).
#include "spinradar/io/png_gray8.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <libdeflate.h>
#include <spng.h>

#if defined(__SSSE3__)
#include <tmmintrin.h>
#endif

namespace spinradar {

namespace {

constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
/// Larger images are refused (libspng then applies its own limits).
constexpr uint64_t kMaxPixelBytes = uint64_t(1) << 30;

uint32_t be32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

bool isType(const uint8_t* t, const char* name) { return std::memcmp(t, name, 4) == 0; }

/// Ancillary chunks that change nothing in what OpenCV returns for a grayscale image.
bool harmlessAncillary(const uint8_t* t) {
  return isType(t, "tEXt") || isType(t, "zTXt") || isType(t, "iTXt") || isType(t, "tIME") || isType(t, "pHYs");
}

struct Header {
  uint32_t width = 0, height = 0;
};

/// Walks the chunks: true when the file is a complete 8-bit grayscale non-interlaced PNG made
/// of IHDR, IDAT, IEND and harmless chunks, with valid CRCs on the critical ones. Appends the
/// image data to `idat` when given.
bool scanChunks(const uint8_t* png, size_t size, Header& h, std::vector<uint8_t>* idat) {
  if (size < 8 || std::memcmp(png, kSignature, 8) != 0) return false;
  if (idat) idat->clear();
  size_t pos = 8;
  bool have_ihdr = false, have_idat = false, idat_done = false;
  while (pos + 12 <= size) {
    const uint32_t len = be32(png + pos);
    const uint8_t* type = png + pos + 4;
    const uint8_t* data = png + pos + 8;
    if (len > 0x7fffffffu || size - pos - 12 < len) return false;  // truncated
    const bool critical = (type[0] & 0x20) == 0;
    if (critical && libdeflate_crc32(0, type, len + 4) != be32(data + len)) return false;
    if (isType(type, "IHDR")) {
      if (have_ihdr || len != 13) return false;
      h.width = be32(data);
      h.height = be32(data + 4);
      // bit depth 8, colour type 0 (gray), compression 0, filter 0, no interlace
      if (data[8] != 8 || data[9] != 0 || data[10] != 0 || data[11] != 0 || data[12] != 0) return false;
      if (h.width == 0 || h.height == 0 || uint64_t(h.width + 1) * h.height > kMaxPixelBytes) return false;
      have_ihdr = true;
    } else if (isType(type, "IDAT")) {
      if (!have_ihdr || idat_done) return false;  // IDATs must be consecutive
      have_idat = true;
      if (idat) idat->insert(idat->end(), data, data + len);
    } else if (isType(type, "IEND")) {
      return have_ihdr && have_idat;
    } else if (!harmlessAncillary(type)) {
      return false;  // PLTE, tRNS, gAMA, unknown critical chunks...: not handled here
    }
    if (have_idat && !isType(type, "IDAT")) idat_done = true;
    pos += size_t(len) + 12;
  }
  return false;  // no IEND: truncated
}

/// Sub filter, one byte per pixel: a running sum along the row (SSE prefix sums, 16 at a time).
void unfilterSub(uint8_t* row, int n) {
  int i = 0;
#if defined(__SSSE3__)
  __m128i carry = _mm_setzero_si128();
  const __m128i last = _mm_set1_epi8(15);
  for (; i + 16 <= n; i += 16) {
    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + i));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 1));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 2));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 4));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 8));
    v = _mm_add_epi8(v, carry);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(row + i), v);
    carry = _mm_shuffle_epi8(v, last);
  }
#endif
  uint8_t left = i > 0 ? row[i - 1] : 0;
  for (; i < n; ++i) row[i] = left = static_cast<uint8_t>(row[i] + left);
}

/// Undoes PNG filter `f` of one row in place (`prev`: the row above, already unfiltered, or
/// zeros). False for an unknown filter type.
bool unfilterRow(uint8_t f, uint8_t* row, const uint8_t* prev, int n) {
  switch (f) {
    case 0: return true;
    case 1: unfilterSub(row, n); return true;
    case 2:
      for (int i = 0; i < n; ++i) row[i] = static_cast<uint8_t>(row[i] + prev[i]);
      return true;
    case 3: {
      int left = 0;
      for (int i = 0; i < n; ++i) row[i] = static_cast<uint8_t>(left = uint8_t(row[i] + ((left + prev[i]) >> 1)));
      return true;
    }
    case 4: {
      int left = 0, upleft = 0;
      for (int i = 0; i < n; ++i) {
        const int up = prev[i];
        const int p = left + up - upleft, pa = std::abs(p - left), pb = std::abs(p - up), pc = std::abs(p - upleft);
        const int pred = (pa <= pb && pa <= pc) ? left : (pb <= pc ? up : upleft);
        row[i] = static_cast<uint8_t>(left = uint8_t(row[i] + pred));
        upleft = up;
      }
      return true;
    }
    default: return false;
  }
}

}  // namespace

struct PngGray8Decoder::Inflater {
  libdeflate_decompressor* d = nullptr;
  Inflater() : d(libdeflate_alloc_decompressor()) {
    if (!d) throw std::bad_alloc();
  }
  ~Inflater() { libdeflate_free_decompressor(d); }
};

const char* pngDecoderName(PngDecoder decoder) {
  switch (decoder) {
    case PngDecoder::Deflate: return "libdeflate + own unfilter";
    default: return "libspng";
  }
}

void readFileBytes(const std::string& path, std::vector<uint8_t>& bytes) {
  // POSIX calls rather than stdio: fopen allocates a FILE and its buffer on every call, and the
  // scan loader must not allocate per scan once warmed up.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot open file");
  struct stat st {};
  size_t n = 0;
  if (::fstat(fd, &st) == 0 && st.st_size > 0) n = size_t(st.st_size);
  bytes.resize(n);  // read straight into the reused buffer, then whatever the size missed
  size_t got = 0;
  bool failed = false;
  uint8_t more[4096];
  for (;;) {
    const bool room = got < bytes.size();
    const ssize_t r = room ? ::read(fd, bytes.data() + got, bytes.size() - got) : ::read(fd, more, sizeof more);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      failed = r < 0;
      break;
    }
    if (!room) bytes.insert(bytes.end(), more, more + r);  // the file grew since fstat
    got += size_t(r);
  }
  ::close(fd);
  bytes.resize(got);
  if (failed) throw std::runtime_error(path + ": read error");
}

PngGray8Decoder::PngGray8Decoder(PngDecoder method) : method_(method), inflater_(std::make_unique<Inflater>()) {}
PngGray8Decoder::~PngGray8Decoder() = default;

bool PngGray8Decoder::decode(const uint8_t* png, size_t size, cv::Mat& image) {
  image.release();
  switch (method_) {
    case PngDecoder::Deflate: return decodeDeflate(png, size, image);
    default: return decodeSpng(png, size, image);
  }
}

bool PngGray8Decoder::decodeDeflate(const uint8_t* png, size_t size, cv::Mat& image) {
  Header h;
  if (!scanChunks(png, size, h, &idat_)) return false;
  const size_t stride = size_t(h.width) + 1;
  pixels_.resize(stride * h.height);
  if (libdeflate_zlib_decompress(inflater_->d, idat_.data(), idat_.size(), pixels_.data(), pixels_.size(),
                                 nullptr) != LIBDEFLATE_SUCCESS)
    return false;  // corrupt, short or long data: refused
  // The row above the first is zeros: give Up/Average/Paeth a zero row to read.
  static const std::vector<uint8_t> zeros(1 << 16, 0);
  std::vector<uint8_t> wide_zeros;
  const uint8_t* prev = zeros.data();
  if (h.width > zeros.size()) {
    wide_zeros.assign(h.width, 0);
    prev = wide_zeros.data();
  }
  for (uint32_t r = 0; r < h.height; ++r) {
    uint8_t* row = pixels_.data() + r * stride;
    if (!unfilterRow(row[0], row + 1, prev, static_cast<int>(h.width))) return false;
    prev = row + 1;
  }
  image = cv::Mat(static_cast<int>(h.height), static_cast<int>(h.width), CV_8UC1, pixels_.data() + 1, stride);
  return true;
}

bool PngGray8Decoder::decodeSpng(const uint8_t* png, size_t size, cv::Mat& image) {
  Header h;
  if (!scanChunks(png, size, h, nullptr)) return false;
  spng_ctx* ctx = spng_ctx_new(0);
  if (!ctx) return false;
  size_t len = 0;
  bool ok = spng_set_png_buffer(ctx, png, size) == 0 && spng_decoded_image_size(ctx, SPNG_FMT_PNG, &len) == 0 &&
            len == size_t(h.width) * h.height;
  if (ok) {
    pixels_.resize(len);
    ok = spng_decode_image(ctx, pixels_.data(), len, SPNG_FMT_PNG, 0) == 0;
  }
  spng_ctx_free(ctx);
  if (!ok) return false;
  image = cv::Mat(static_cast<int>(h.height), static_cast<int>(h.width), CV_8UC1, pixels_.data());
  return true;
}

}  // namespace spinradar
