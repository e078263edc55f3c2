// Round trips of the Oxford/Boreas layouts and rejection of corrupt files with named reasons.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include "support/temp_dir.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

using spinradar::test::TempDir;

namespace {

PolarScan makeScan(int azimuths, int bins, int64_t t0_us, unsigned seed = 1) {
  PolarScan s;
  s.resize(azimuths, bins);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(0, 255);
  for (auto& p : s.power) p = static_cast<uint8_t>(u(rng));
  const int step = 5600 / azimuths;
  for (int a = 0; a < azimuths; ++a) {
    s.encoder[a] = static_cast<uint16_t>((13 + a * step) % 5600);
    s.azimuth[a] = 2.0 * M_PI * s.encoder[a] / 5600.0;
    s.stamp_ns[a] = (t0_us + a * 625) * 1000;
  }
  return s;
}

void expectThrowsWith(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    for (const auto& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << "'" << e.what() << "' lacks '" << p << "'";
  }
}

std::string captureWarnings(const std::function<void()>& f) {
  std::string all;
  setScanWarningHandler([&](const std::string& m) { all += m + "\n"; });
  f();
  setScanWarningHandler(nullptr);
  return all;
}

}  // namespace

TEST(ScanIo, OxfordRoundTrip) {
  TempDir d;
  PolarScan s = makeScan(400, 3768, 1547131046353776LL);
  s.valid[5] = 0;
  const std::string p = d.file("1547131046353776.png");
  saveOxfordPng(s, p);
  const PolarScan r = loadOxfordPng(p, 0.0432, 0.1);
  ASSERT_EQ(r.azimuths, 400);
  ASSERT_EQ(r.bins, 3768);
  EXPECT_DOUBLE_EQ(r.range_resolution, 0.0432);
  EXPECT_DOUBLE_EQ(r.range_offset, 0.1);
  EXPECT_EQ(r.power, s.power);
  EXPECT_EQ(r.encoder, s.encoder);
  EXPECT_EQ(r.stamp_ns, s.stamp_ns);
  EXPECT_EQ(r.valid, s.valid);
  for (int a = 0; a < 400; ++a) EXPECT_NEAR(r.azimuth[a], s.azimuth[a], 1e-12);
  EXPECT_NEAR(r.azimuth[0], 13.0 / 5600.0 * 2 * M_PI, 1e-12);
  EXPECT_TRUE(r.chirp_up.empty());
  // In-memory encode/decode agrees with the file.
  cv::Mat img;
  encodeOxfordImage(s, img);
  EXPECT_EQ(decodeOxfordImage(img, "mem").power, s.power);
}

TEST(ScanIo, OtherEncoderSizesAreWrittenAsAnglesOf5600) {
  TempDir d;
  PolarScan s = makeScan(400, 20, 1000);
  s.encoder_size = 4000;
  for (int a = 0; a < 400; ++a) {
    s.encoder[a] = static_cast<uint16_t>(a * 10);
    s.azimuth[a] = 2 * M_PI * a / 400.0;
  }
  saveOxfordPng(s, d.file("e.png"));
  const PolarScan r = loadOxfordPng(d.file("e.png"));
  for (int a = 0; a < 400; ++a) EXPECT_NEAR(r.azimuth[a], s.azimuth[a], 1e-12) << a;
  EXPECT_EQ(r.encoder[1], 14);
}

TEST(ScanIo, BoreasRoundTripBothFirmwaresAndChirps) {
  TempDir d;
  for (int bins : {3360, 6848}) {
    PolarScan s = makeScan(400, bins, 1606417230000000LL, bins);
    s.chirp_up.resize(400);
    for (int a = 0; a < 400; ++a) s.chirp_up[a] = a % 2;
    const std::string p = d.file(std::to_string(boreasFileStampUs(s)) + ".png");
    saveBoreasPng(s, p);
    const PolarScan r = loadBoreasPng(p);
    ASSERT_EQ(r.bins, bins);
    EXPECT_DOUBLE_EQ(r.range_resolution, bins == 3360 ? 0.0596 : 0.04381);
    EXPECT_DOUBLE_EQ(r.range_offset, -0.31);
    EXPECT_EQ(r.power, s.power);
    EXPECT_EQ(r.stamp_ns, s.stamp_ns);
    EXPECT_EQ(r.chirp_up, s.chirp_up);
    EXPECT_EQ(std::count(r.valid.begin(), r.valid.end(), 1), 400);
    EXPECT_EQ(boreasFileStampUs(r), 1606417230000000LL + 200 * 625);
  }
  // The CIR204-H's firmware upgrade of 2021-09-21 kept 3360 bins but made them 0.04381 m.
  PolarScan later = makeScan(400, 3360, 1634050000000000LL);
  saveBoreasPng(later, d.file("later.png"));
  EXPECT_DOUBLE_EQ(loadBoreasPng(d.file("later.png")).range_resolution, 0.04381);
  // Without chirps, column 10 is not read as chirps.
  PolarScan s = makeScan(400, 3360, 1606417230000000LL);
  saveBoreasPng(s, d.file("b.png"));
  EXPECT_TRUE(loadBoreasPng(d.file("b.png")).chirp_up.empty());
}

TEST(ScanIo, MissingAndDuplicatedRowsAreInvalid) {
  TempDir d;
  PolarScan s = makeScan(400, 100, 1000000);
  s.stamp_ns[10] = 0;
  s.encoder[10] = 0;  // zero-filled row
  s.encoder[20] = s.encoder[19];  // repeated packet
  saveOxfordPng(s, d.file("m.png"));
  const PolarScan r = loadOxfordPng(d.file("m.png"));
  EXPECT_EQ(r.valid[10], 0);
  EXPECT_EQ(r.valid[20], 0);
  EXPECT_EQ(std::count(r.valid.begin(), r.valid.end(), 0), 2);
  // The missing row gets interpolated geometry.
  EXPECT_NEAR(r.azimuth[10], 0.5 * (r.azimuth[9] + r.azimuth[11]), 1e-9);
  EXPECT_EQ(r.stamp_ns[10], (r.stamp_ns[9] + r.stamp_ns[11]) / 2);
}

TEST(ScanIo, NonMonotonicStampsWarnButLoad) {
  TempDir d;
  PolarScan s = makeScan(400, 50, 1000000);
  std::swap(s.stamp_ns[30], s.stamp_ns[31]);
  saveOxfordPng(s, d.file("w.png"));
  PolarScan r;
  const std::string w = captureWarnings([&] { r = loadOxfordPng(d.file("w.png")); });
  EXPECT_EQ(r.azimuths, 400);
  EXPECT_NE(w.find("w.png"), std::string::npos) << w;
  EXPECT_NE(w.find("row 31"), std::string::npos) << w;
  EXPECT_NE(w.find("not monotonic"), std::string::npos) << w;
}

TEST(ScanIo, CorruptFilesAreRejectedWithTheReason) {
  TempDir d;
  // Missing file.
  expectThrowsWith([&] { loadOxfordPng(d.file("none.png")); }, {"none.png", "cannot open"});
  // Not a PNG.
  {
    std::ofstream(d.file("text.png")) << "hello, not an image";
    expectThrowsWith([&] { loadOxfordPng(d.file("text.png")); }, {"text.png", "not a PNG"});
  }
  // Truncated PNG.
  {
    PolarScan s = makeScan(400, 200, 1);
    saveOxfordPng(s, d.file("full.png"));
    std::ifstream in(d.file("full.png"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(d.file("trunc.png"), std::ios::binary).write(bytes.data(), bytes.size() / 2);
    expectThrowsWith([&] { loadOxfordPng(d.file("trunc.png")); }, {"trunc.png", "unreadable PNG"});
  }
  // Too narrow for the metadata.
  cv::imwrite(d.file("narrow.png"), cv::Mat(400, 8, CV_8UC1, cv::Scalar(0)));
  expectThrowsWith([&] { loadOxfordPng(d.file("narrow.png")); }, {"narrow.png", "8 columns", "11"});
  // Colour image.
  cv::imwrite(d.file("rgb.png"), cv::Mat(400, 100, CV_8UC3, cv::Scalar(0)));
  expectThrowsWith([&] { loadOxfordPng(d.file("rgb.png")); }, {"rgb.png", "3 channel", "8-bit single-channel"});
  // 16-bit image.
  cv::imwrite(d.file("deep.png"), cv::Mat(400, 100, CV_16UC1, cv::Scalar(0)));
  expectThrowsWith([&] { loadOxfordPng(d.file("deep.png")); }, {"deep.png", "16-bit"});
  // Encoder out of range.
  {
    PolarScan s = makeScan(400, 50, 1);
    s.encoder[17] = 6000;
    saveOxfordPng(s, d.file("enc.png"));
    expectThrowsWith([&] { loadOxfordPng(d.file("enc.png")); }, {"enc.png", "row 17", "encoder 6000 >= 5600"});
    // On the first row: most likely another layout (a RADIATE image read as Oxford); say so.
    s.encoder[17] = 17;
    s.encoder[0] = 16193;
    saveOxfordPng(s, d.file("enc0.png"));
    expectThrowsWith([&] { loadOxfordPng(d.file("enc0.png")); },
                     {"enc0.png", "row 0", "encoder 16193 >= 5600", "--format radiate"});
  }
  // Boreas widths other than 3360 / 6848 bins.
  {
    PolarScan s = makeScan(400, 3768, 1);
    saveOxfordPng(s, d.file("oxf.png"));
    expectThrowsWith([&] { loadBoreasPng(d.file("oxf.png")); }, {"oxf.png", "3779 columns", "3360", "6848"});
  }
  // Writing: non-PNG name, unwritable folder, empty scan.
  PolarScan s = makeScan(10, 10, 1);
  expectThrowsWith([&] { saveOxfordPng(s, d.file("x.jpg")); }, {"x.jpg", ".png"});
  expectThrowsWith([&] { saveOxfordPng(s, d.file("no/such/dir/x.png")); }, {"x.png", "cannot write"});
  expectThrowsWith([&] { saveOxfordPng(PolarScan{}, d.file("e.png")); }, {"e.png", "empty"});
}

TEST(ScanIo, MulranCsvParsesAndRejectsBadLines) {
  TempDir d;
  {
    std::ofstream f(d.file("100.csv"));
    for (int a = 0; a < 16; ++a) {
      f << (1000000000LL + a * 625000) << "," << (a * 0.9) << "," << (9 + 14 * a) << "," << (42 + a);
      for (int b = 0; b < 16; ++b) f << "," << (a * 10 + b);
      f << "\n";
    }
  }
  const PolarScan s = loadMulranCsv(d.file("100.csv"));
  ASSERT_EQ(s.azimuths, 16);
  ASSERT_EQ(s.bins, 16);
  EXPECT_EQ(s.stamp_ns[3], 1000000000LL + 3 * 625000);
  EXPECT_EQ(s.row(2)[5], 25);
  EXPECT_NEAR(s.azimuth[1], 23.0 / 5600 * 2 * M_PI, 1e-12);
  EXPECT_DOUBLE_EQ(s.range_resolution, 0.0595238);

  std::ofstream(d.file("short.csv")) << "1,0,9,1,1,2,3\n2,0,23,2,1,2\n";
  expectThrowsWith([&] { loadMulranCsv(d.file("short.csv")); }, {"short.csv", "line 2", "2 bins but 3 expected"});
  std::ofstream(d.file("big.csv")) << "1,0,9,1,1,300,3\n";
  expectThrowsWith([&] { loadMulranCsv(d.file("big.csv")); }, {"big.csv", "line 1", "300"});
  std::ofstream(d.file("word.csv")) << "1,0,nine,1,1,2,3\n";
  expectThrowsWith([&] { loadMulranCsv(d.file("word.csv")); }, {"word.csv", "line 1", "encoder"});
  std::ofstream(d.file("enc.csv")) << "1,0,5600,1,1,2,3\n";
  expectThrowsWith([&] { loadMulranCsv(d.file("enc.csv")); }, {"enc.csv", "encoder 5600 >= 5600"});
  std::ofstream(d.file("empty.csv")) << "";
  expectThrowsWith([&] { loadMulranCsv(d.file("empty.csv")); }, {"empty.csv", "no data"});
}

TEST(ScanIo, RadiateTransposesAndSynthesisesStamps) {
  TempDir d;
  cv::Mat img(576, 400, CV_8UC1);
  for (int r = 0; r < 576; ++r)
    for (int c = 0; c < 400; ++c) img.at<uint8_t>(r, c) = static_cast<uint8_t>((r + 3 * c) & 0xff);
  cv::imwrite(d.file("000001.png"), img);
  const PolarScan s = loadRadiatePng(d.file("000001.png"), 5000000000LL);
  ASSERT_EQ(s.azimuths, 400);
  ASSERT_EQ(s.bins, 576);
  EXPECT_EQ(s.row(7)[100], static_cast<uint8_t>((100 + 21) & 0xff));
  EXPECT_EQ(s.stamp_ns[0], 5000000000LL);
  EXPECT_EQ(s.stamp_ns[200], 5000000000LL + 125000000LL);
  EXPECT_NEAR(s.azimuth[100], M_PI / 2, 1e-12);
}

TEST(ScanFolder, ListsSortedAndGuessesFormat) {
  TempDir d;
  fs::create_directories(d.path / "radar");
  for (int64_t t : {3000000LL, 1000000LL, 2000000LL}) {
    PolarScan s = makeScan(400, 3768, t);
    saveOxfordPng(s, (d.path / "radar" / (std::to_string(t) + ".png")).string());
  }
  ScanFolder f(d.path.string());
  EXPECT_EQ(f.format(), ScanFormat::Oxford);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f.fileStampNs(0), 1000000000LL);
  EXPECT_EQ(f.fileStampNs(2), 3000000000LL);
  EXPECT_EQ(f.load(1).stamp_ns[0], 2000000000LL);

  // A mis-sized scan in the folder is named on load.
  saveOxfordPng(makeScan(400, 3000, 4000000LL), (d.path / "radar" / "4000000.png").string());
  ScanFolder g(d.path.string());
  EXPECT_EQ(g.expectedBins(), 3768);
  expectThrowsWith([&] { g.load(3); }, {"4000000.png", "3011 columns but 11 + 3768 bins expected"});

  TempDir b;
  saveBoreasPng(makeScan(400, 6848, 7), b.file("7.png"));
  EXPECT_EQ(ScanFolder(b.path.string()).format(), ScanFormat::Boreas);

  TempDir e;
  expectThrowsWith([&] { ScanFolder x(e.path.string()); }, {e.path.string(), "no scan files"});
  expectThrowsWith([&] { ScanFolder x(e.file("nope")); }, {"nope", "not a folder"});
  std::ofstream(e.file("abc.png")) << "x";
  expectThrowsWith([&] { ScanFolder x(e.path.string(), ScanFormat::Oxford); }, {"abc.png", "not a number"});
  EXPECT_EQ(parseScanFormat("mulran"), ScanFormat::MulRan);
  EXPECT_THROW(parseScanFormat("kitti"), std::invalid_argument);
}
