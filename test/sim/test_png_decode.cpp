// The fast PNG decoders give exactly OpenCV's bytes: on Oxford-layout scans written by the
// project (simulated city scans), on every PNG row filter, on the real Oxford sample, and they
// refuse anything else (colour, 16-bit, damaged files). The libspng writer (plots, scans) gives
// back what OpenCV reads.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>
#include <spng.h>

#include "support/count_allocations.hpp"
#include "support/temp_dir.hpp"
#include "spinradar/io/png_gray8.hpp"
#include "spinradar/io/png_io.hpp"
#include "spinradar/io/scan_io.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

using spinradar::test::TempDir;

namespace {

const PngDecoder kFast[] = {PngDecoder::Deflate, PngDecoder::Spng};

std::vector<uint8_t> fileBytes(const std::string& path) {
  std::vector<uint8_t> b;
  readFileBytes(path, b);
  return b;
}

cv::Mat openCvDecode(const std::vector<uint8_t>& png) {
  return cv::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8UC1, const_cast<uint8_t*>(png.data())),
                      cv::IMREAD_UNCHANGED);
}

/// Number of bytes that differ (-1 when the sizes or types differ).
long differences(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  long n = 0;
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c) n += a.at<uint8_t>(r, c) != b.at<uint8_t>(r, c);
  return n;
}

void expectSameAsOpenCv(const std::vector<uint8_t>& png, const std::string& what) {
  const cv::Mat ref = openCvDecode(png);
  ASSERT_FALSE(ref.empty()) << what;
  for (PngDecoder m : kFast) {
    PngGray8Decoder dec(m);
    cv::Mat img;
    ASSERT_TRUE(dec.decode(png.data(), png.size(), img)) << what << ", " << pngDecoderName(m);
    EXPECT_EQ(differences(img, ref), 0) << what << ", " << pngDecoderName(m);
    // A second decode into the same buffers gives the same again.
    ASSERT_TRUE(dec.decode(png.data(), png.size(), img));
    EXPECT_EQ(differences(img, ref), 0) << what << " (second decode), " << pngDecoderName(m);
  }
}

/// Encodes `img` (CV_8UC1) with libspng using only the given row filter(s).
std::vector<uint8_t> encodeWithFilter(const cv::Mat& img, int filter_choice, int level) {
  spng_ctx* ctx = spng_ctx_new(SPNG_CTX_ENCODER);
  spng_set_option(ctx, SPNG_ENCODE_TO_BUFFER, 1);
  spng_set_option(ctx, SPNG_FILTER_CHOICE, filter_choice);
  spng_set_option(ctx, SPNG_IMG_COMPRESSION_LEVEL, level);
  spng_ihdr ihdr{};
  ihdr.width = static_cast<uint32_t>(img.cols);
  ihdr.height = static_cast<uint32_t>(img.rows);
  ihdr.bit_depth = 8;
  ihdr.color_type = SPNG_COLOR_TYPE_GRAYSCALE;
  spng_set_ihdr(ctx, &ihdr);
  const cv::Mat c = img.isContinuous() ? img : img.clone();
  int err = spng_encode_image(ctx, c.data, c.total(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  size_t len = 0;
  void* buf = err == 0 ? spng_get_png_buffer(ctx, &len, &err) : nullptr;
  std::vector<uint8_t> out;
  if (buf) out.assign(static_cast<uint8_t*>(buf), static_cast<uint8_t*>(buf) + len);
  std::free(buf);
  spng_ctx_free(ctx);
  return out;
}


}  // namespace

TEST(PngDecode, SimulatedOxfordScansDecodeExactlyAsOpenCv) {
  sim::Scene scene = sim::builtinScene("city");
  sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  sim::Simulator simulator(scene.world, scene.trajectory, sim::SensorConfig{}, physics, 7);
  TempDir d;
  for (int k : {20, 60}) {
    const PolarScan s = simulator.renderScan(k);
    ASSERT_EQ(s.bins, 3768);
    const std::string path = d.file(std::to_string(k) + ".png");
    saveOxfordPng(s, path);
    const std::vector<uint8_t> png = fileBytes(path);
    expectSameAsOpenCv(png, "simulated scan " + std::to_string(k));
    // And the loader (fast path) returns the scan that was written.
    const PolarScan r = loadOxfordPng(path);
    ASSERT_EQ(r.power.size(), s.power.size());
    EXPECT_TRUE(r.power == s.power) << "scan " << k;
    EXPECT_TRUE(r.encoder == s.encoder);
  }
}

TEST(PngDecode, EveryRowFilterAndCompressionLevel) {
  // Radar-like rows: speckle plus a few strong returns, sizes not multiples of 16.
  std::mt19937 rng(3);
  cv::Mat img(37, 1001, CV_8UC1);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c)
      img.at<uint8_t>(r, c) = static_cast<uint8_t>(rng() % 40 + (c % 97 == 5 ? 200 : 0));
  const std::pair<int, const char*> filters[] = {
      {SPNG_FILTER_CHOICE_NONE, "none"}, {SPNG_FILTER_CHOICE_SUB, "sub"}, {SPNG_FILTER_CHOICE_UP, "up"},
      {SPNG_FILTER_CHOICE_AVG, "average"}, {SPNG_FILTER_CHOICE_PAETH, "paeth"}, {SPNG_FILTER_CHOICE_ALL, "mixed"}};
  for (const auto& [f, name] : filters)
    for (int level : {1, 9}) {
      const std::vector<uint8_t> png = encodeWithFilter(img, f, level);
      ASSERT_FALSE(png.empty()) << name;
      expectSameAsOpenCv(png, std::string("filter ") + name + ", level " + std::to_string(level));
    }
  // One-pixel-wide and 16-wide images (no tail / no SIMD block).
  for (int w : {1, 16, 17}) {
    cv::Mat m(5, w, CV_8UC1);
    cv::randu(m, 0, 256);
    expectSameAsOpenCv(encodeWithFilter(m, SPNG_FILTER_CHOICE_ALL, 6), "width " + std::to_string(w));
  }
}

TEST(PngDecode, OtherKindsAndDamagedFilesAreRefusedByTheFastPath) {
  std::vector<uint8_t> buf;
  auto encode = [&](const cv::Mat& m) {
    cv::imencode(".png", m, buf);
    return buf;
  };
  for (PngDecoder m : kFast) {
    PngGray8Decoder dec(m);
    cv::Mat img;
    const std::vector<uint8_t> rgb = encode(cv::Mat(20, 30, CV_8UC3, cv::Scalar(1, 2, 3)));
    EXPECT_FALSE(dec.decode(rgb.data(), rgb.size(), img)) << "colour, " << pngDecoderName(m);
    EXPECT_TRUE(img.empty());
    const std::vector<uint8_t> deep = encode(cv::Mat(20, 30, CV_16UC1, cv::Scalar(1000)));
    EXPECT_FALSE(dec.decode(deep.data(), deep.size(), img)) << "16-bit, " << pngDecoderName(m);
    std::vector<uint8_t> good = encode(cv::Mat(20, 30, CV_8UC1, cv::Scalar(7)));
    ASSERT_TRUE(dec.decode(good.data(), good.size(), img));
    EXPECT_EQ(img.at<uint8_t>(19, 29), 7);
    // Truncated: no IEND.
    EXPECT_FALSE(dec.decode(good.data(), good.size() - 20, img)) << pngDecoderName(m);
    // One flipped byte of image data: the CRC no longer matches (libpng refuses it too).
    std::vector<uint8_t> bad = good;
    bad[bad.size() - 12 - 6] ^= 0x40;  // inside the last IDAT, before its CRC and IEND
    EXPECT_FALSE(dec.decode(bad.data(), bad.size(), img)) << pngDecoderName(m);
    EXPECT_TRUE(openCvDecode(bad).empty()) << "OpenCV also rejects the flipped byte";
  }
}

TEST(PngDecode, RealOxfordScansDecodeExactlyAsOpenCv) {
  const fs::path dir = fs::path(SPINRADAR_SHARED_DIR) / "realdata/oxford_2019-01-10-14-36-48/radar";
  if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " not present (../shared/realdata)";
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".png") continue;
    expectSameAsOpenCv(fileBytes(e.path().string()), e.path().filename().string());
    ++n;
  }
  EXPECT_GE(n, 3);
}

TEST(PngDecode, WriterRoundTripsThroughOpenCv) {
  TempDir d;
  cv::Mat bgr(31, 45, CV_8UC3), bgra(7, 9, CV_8UC4), gray(13, 70, CV_8UC1);
  cv::randu(bgr, 0, 256);
  cv::randu(bgra, 0, 256);
  cv::randu(gray, 0, 256);
  for (const cv::Mat& m : {bgr, bgra, gray}) {
    const std::string path = d.file("w" + std::to_string(m.channels()) + ".png");
    writePng(m, path, 6);
    const cv::Mat back = cv::imread(path, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.type(), m.type()) << m.channels() << " channels";
    EXPECT_EQ(cv::norm(back, m, cv::NORM_INF), 0) << m.channels() << " channels (BGR order kept)";
  }
  EXPECT_EQ(differences(readPngGray8(d.file("w1.png")), gray), 0);
  try {
    readPngGray8(d.file("w3.png"));
    ADD_FAILURE() << "colour accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("w3.png: 3 channel(s) of 8-bit"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writePng(gray, d.file("no/such/folder/x.png")), std::runtime_error);
  EXPECT_FALSE(fs::exists(d.file("no/such/folder/x.png.tmp")));
}

TEST(PngDecode, NoAllocationPerScanAfterWarmUp) {
  // Decoding the next scan of a drive reuses the decoder's and the reader's buffers.
  sim::Scene scene = sim::builtinScene("city");
  sim::Simulator simulator(scene.world, scene.trajectory, sim::SensorConfig{}, sim::PhysicsConfig{}, 3);
  TempDir d;
  const std::string a = d.file("a.png"), b = d.file("b.png");
  saveOxfordPng(simulator.renderScan(10), a);
  saveOxfordPng(simulator.renderScan(11), b);
  const std::vector<uint8_t> pa = fileBytes(a), pb = fileBytes(b);
  PngGray8Decoder dec;
  cv::Mat img;
  for (int warm = 0; warm < 2; ++warm) {
    ASSERT_TRUE(dec.decode(pa.data(), pa.size(), img));
    readPngGray8(a);
    readPngGray8(b);
  }
  long before = g_allocations;
  ASSERT_TRUE(dec.decode(pb.data(), pb.size(), img));
  EXPECT_EQ(g_allocations - before, 0) << "PngGray8Decoder::decode";
  before = g_allocations;
  const cv::Mat r = readPngGray8(b);
  EXPECT_EQ(g_allocations - before, 0) << "readPngGray8 (file read + decode)";
  EXPECT_EQ(r.cols, 3768 + kNavtechMetaColumns);
}
