// Bad scan files and folders: format guessed only when unambiguous, shapes checked against the
// format, numbers from names and rows checked, each failure naming the file and the reason.
#include <gtest/gtest.h>


#include <filesystem>
#include <fstream>
#include <functional>

#include <opencv2/imgcodecs.hpp>

#include "support/temp_dir.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

using spinradar::test::TempDir;

namespace {

PolarScan makeScan(int azimuths, int bins, int64_t t0_us) {
  PolarScan s;
  s.resize(azimuths, bins);
  for (size_t i = 0; i < s.power.size(); ++i) s.power[i] = static_cast<uint8_t>(i * 7);
  for (int a = 0; a < azimuths; ++a) {
    s.encoder[a] = static_cast<uint16_t>((13 + a * (5600 / azimuths)) % 5600);
    s.azimuth[a] = 2.0 * M_PI * s.encoder[a] / 5600.0;
    s.stamp_ns[a] = (t0_us + a * 625) * 1000;
  }
  return s;
}

void expectError(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "expected an error";
  } catch (const std::exception& e) {
    for (const auto& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << "'" << e.what() << "' lacks '" << p << "'";
  }
}

}  // namespace

TEST(BadScans, FormatIsGuessedOnlyWhenUnambiguous) {
  TempDir narrow;  // 12 columns: no room for Oxford metadata, no Navtech_Polar.txt either
  cv::imwrite(narrow.file("1547131046353776.png"), cv::Mat(400, 12, CV_8UC1, cv::Scalar(0)));
  expectError([&] { ScanFolder f(narrow.path.string()); },
              {"cannot tell the scan format", "1547131046353776.png is 12 x 400", "--format"});

  TempDir plain;  // transposed-looking image without RADIATE's times file
  cv::imwrite(plain.file("000001.png"), cv::Mat(576, 400, CV_8UC1, cv::Scalar(7)));
  expectError([&] { ScanFolder f(plain.path.string()); },
              {"cannot tell the scan format", "400 x 576", "Navtech_Polar.txt", "--format"});

  TempDir mixed;
  saveOxfordPng(makeScan(400, 100, 1000), mixed.file("1000.png"));
  std::ofstream(mixed.file("2000.csv")) << "1,0,9,1,1\n";
  expectError([&] { ScanFolder f(mixed.path.string()); }, {"both .png", ".csv", "--format"});

  TempDir ok;  // Oxford rows are recognised from their metadata, whatever the width
  saveOxfordPng(makeScan(400, 100, 1000), ok.file("1000.png"));
  EXPECT_EQ(ScanFolder(ok.path.string()).format(), ScanFormat::Oxford);
}

TEST(BadScans, ShapesAreCheckedAgainstTheFormat) {
  TempDir d;
  saveOxfordPng(makeScan(10, 100, 1000), d.file("rows10.png"));
  expectError([&] { loadOxfordPng(d.file("rows10.png")); }, {"rows10.png", "10 azimuths (rows)"});
  saveOxfordPng(makeScan(400, 1, 1000), d.file("bins1.png"));
  expectError([&] { loadOxfordPng(d.file("bins1.png")); }, {"bins1.png", "1 range bins"});
  // Oxford data read as RADIATE: 3779 azimuths across.
  saveOxfordPng(makeScan(400, 3768, 1000), d.file("oxford.png"));
  expectError([&] { loadRadiatePng(d.file("oxford.png"), 0); },
              {"oxford.png", "3779 x 400", "400 azimuths across", "--format oxford"});
  // A MulRan CSV cut inside its first line.
  std::ofstream(d.file("cut.csv")) << "1564718976161407002,0.0,9,1,12,40,3";
  expectError([&] { loadMulranCsv(d.file("cut.csv")); }, {"cut.csv", "1 azimuths (lines)"});
  // A constant encoder leaves one usable row.
  PolarScan c = makeScan(400, 50, 1000);
  std::fill(c.encoder.begin(), c.encoder.end(), uint16_t(100));
  saveOxfordPng(c, d.file("const.png"));
  expectError([&] { loadOxfordPng(d.file("const.png")); },
              {"const.png", "only 1 of 400 rows are valid", "399 repeat the encoder"});
}

TEST(BadScans, NumbersOutOfRangeAreNamedErrors) {
  TempDir d;
  fs::create_directories(d.path / "radar");
  saveOxfordPng(makeScan(400, 100, 1000), (d.path / "radar" / "9999999999999999999.png").string());
  expectError([&] { ScanFolder f(d.path.string(), ScanFormat::Oxford); },
              {"9999999999999999999.png", "19 digits", "does not fit in 64 bits"});
  fs::remove(d.path / "radar" / "9999999999999999999.png");
  saveOxfordPng(makeScan(400, 100, 1000), (d.path / "radar" / "99999999999999999.png").string());
  expectError([&] { ScanFolder f(d.path.string(), ScanFormat::Oxford); },
              {"99999999999999999.png", "stamp in the file name (us)", "does not fit in 64 bits"});
  // RADIATE frame numbers times the rotation period (no Navtech_Polar.txt).
  expectError([&] { ScanFolder f(d.path.string(), ScanFormat::Radiate); },
              {"99999999999999999.png", "frame number x rotation period"});
  // A stamp near 2^62 us inside the rows.
  TempDir e;
  PolarScan s = makeScan(400, 100, 0);
  for (int a = 0; a < 400; ++a) s.stamp_ns[a] = 0;
  saveOxfordPng(s, e.file("big.png"));
  {
    // Patch row 0's stamp to 2^62 us (more than int64 ns can hold).
    cv::Mat img = cv::imread(e.file("big.png"), cv::IMREAD_UNCHANGED);
    const uint64_t us = uint64_t(1) << 62;
    for (int k = 0; k < 8; ++k) img.at<uint8_t>(0, k) = uint8_t(us >> (8 * k));
    img.at<uint8_t>(0, 8) = 1;
    cv::imwrite(e.file("big.png"), img);
  }
  expectError([&] { loadOxfordPng(e.file("big.png")); }, {"big.png", "row 0", "out of range"});
  // RADIATE times file with an out-of-range time.
  TempDir r;
  fs::create_directories(r.path / "Navtech_Polar");
  cv::imwrite((r.path / "Navtech_Polar" / "000001.png").string(), cv::Mat(576, 400, CV_8UC1, cv::Scalar(1)));
  std::ofstream(r.file("Navtech_Polar.txt")) << "Frame: 000001 Time: 99999999999.5\n";
  expectError([&] { ScanFolder f(r.path.string()); }, {"Navtech_Polar.txt", "line 1", "99999999999.5"});
}

TEST(BadScans, DanglingLinksAreNamedAndSkipped) {
  TempDir d;
  saveOxfordPng(makeScan(400, 100, 1000), d.file("1000.png"));
  fs::create_symlink(d.file("missing.png"), d.file("2000.png"));
  std::string warnings;
  setScanWarningHandler([&](const std::string& m) { warnings += m + "\n"; });
  const ScanFolder f(d.path.string());
  setScanWarningHandler(nullptr);
  EXPECT_EQ(f.size(), 1u);
  EXPECT_NE(warnings.find("2000.png: dangling link skipped"), std::string::npos) << warnings;
}
