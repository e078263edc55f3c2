// libFuzzer target for the file readers: Oxford/Boreas PNG rows, MulRan CSV, RADIATE PNG with
// Navtech_Polar.txt (each also through ScanFolder: format guess, stamps from file names), pose
// and ground-truth CSVs, and the capture reader. SPINRADAR_FUZZ_READER picks one (png, mulran,
// radiate, csv, capture; test/fuzz.cmake runs each for a bounded time). A reader must return a
// consistent result or throw a std::exception naming the problem: a crash, a sanitizer report
// (overflow, out-of-bounds, ...) or a hang is a bug.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "spinradar/driver/capture.hpp"
#include "spinradar/io/ground_truth_io.hpp"
#include "spinradar/io/poses_io.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

namespace fs = std::filesystem;
using namespace spinradar;

namespace {

const std::string& workDir() {
  static const std::string dir = [] {
    const fs::path d = fs::temp_directory_path() / ("spinradar_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    setScanWarningHandler([](const std::string&) {});  // warnings are fine, and noisy
    return d.string();
  }();
  return dir;
}

struct Input {
  const uint8_t* p;
  size_t n;
  uint8_t byte() {
    if (!n) return 0;
    --n;
    return *p++;
  }
};

void writeFile(const std::string& path, const uint8_t* p, size_t n) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(p), std::streamsize(n));
}

/// A file name stem of up to 24 digits (stamps, frame numbers, overflows), or not a number.
std::string stem(Input& in) {
  const int len = in.byte() % 25;
  if (len == 0) return "frame";
  std::string s;
  for (int i = 0; i < len; ++i) s += char('0' + in.byte() % 10);
  return s;
}

/// The rest of the input as an 8-bit image of a fuzzed size (zeros past the data), PNG-encoded:
/// the readers' own logic sees far more cases than through random PNG bytes.
void writeImage(const std::string& path, Input& in, int max_w, int max_h) {
  const int w = 1 + (in.byte() | (in.byte() << 8)) % max_w;
  const int h = 1 + (in.byte() | (in.byte() << 8)) % max_h;
  cv::Mat img(h, w, CV_8UC1, cv::Scalar(0));
  const size_t k = std::min(in.n, img.total());
  std::memcpy(img.data, in.p, k);
  in.p += k;
  in.n -= k;
  cv::imwrite(path, img, {cv::IMWRITE_PNG_COMPRESSION, 0});
}

void checkScan(const PolarScan& s) {
  const size_t a = size_t(s.azimuths);
  if (s.azimuths <= 0 || s.bins <= 0 || s.power.size() != a * size_t(s.bins) ||
      s.stamp_ns.size() != a || s.encoder.size() != a || s.azimuth.size() != a || s.valid.size() != a)
    __builtin_trap();
}

template <class F>
void expectCleanly(F&& f) {
  try {
    f();
  } catch (const std::exception&) {
    // a named error: fine
  }
}

void scanFolderOf(const std::string& dir) {
  expectCleanly([&] {
    const ScanFolder folder(dir);
    for (size_t i = 0; i < folder.size() && i < 2; ++i) checkScan(folder.load(i));
  });
}

void fuzzPng(Input in) {
  const std::string dir = workDir() + "/png";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = dir + "/" + stem(in) + ".png";
  if (in.byte() & 1)
    writeFile(path, in.p, in.n);  // raw bytes: the PNG signature and chunk checks
  else
    writeImage(path, in, 4000, 600);  // Oxford / Boreas widths, 400 rows and more
  expectCleanly([&] { checkScan(loadOxfordPng(path)); });
  expectCleanly([&] { checkScan(loadBoreasPng(path)); });
  scanFolderOf(dir);
}

void fuzzMulran(Input in) {
  const std::string dir = workDir() + "/mulran";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = dir + "/" + stem(in) + ".csv";
  writeFile(path, in.p, in.n);
  expectCleanly([&] { checkScan(loadMulranCsv(path)); });
  scanFolderOf(dir);
}

void fuzzRadiate(Input in) {
  const std::string root = workDir() + "/radiate";
  fs::remove_all(root);
  fs::create_directories(root + "/Navtech_Polar");
  // Navtech_Polar.txt: the next n bytes (n from the input), then the image.
  const size_t txt = std::min<size_t>(in.byte() * 2, in.n);
  writeFile(root + "/Navtech_Polar.txt", in.p, txt);
  in.p += txt;
  in.n -= txt;
  const std::string path = root + "/Navtech_Polar/" + stem(in) + ".png";
  int64_t stamp = 0;
  for (int i = 0; i < 8; ++i) stamp = int64_t(uint64_t(stamp) << 8 | in.byte());
  writeImage(path, in, 800, 800);
  expectCleanly([&] { checkScan(loadRadiatePng(path, stamp)); });
  scanFolderOf(root);
}

void fuzzCsv(Input in) {
  const std::string path = workDir() + "/poses.csv";
  writeFile(path, in.p, in.n);
  expectCleanly([&] { readPoseCsv(path); });
  expectCleanly([&] { readGroundTruth(path); });
  expectCleanly([&] { readOxfordRadarOdometry(path); });
  expectCleanly([&] { readBoreasPoses(path); });
  expectCleanly([&] { readMulranGlobalPose(path); });
}

void fuzzCapture(Input in) {
  const std::string path = workDir() + "/capture.bin";
  {
    std::ofstream f(path, std::ios::binary);
    if (in.byte() & 1) f.write("SPINCAP1", 8);  // past the magic most of the time
    f.write(reinterpret_cast<const char*>(in.p), std::streamsize(in.n));
  }
  expectCleanly([&] {
    navtech::CaptureReader reader(path);
    navtech::CaptureReader::Record r;
    for (int i = 0; i < 100000 && reader.next(r); ++i) {
    }
    if (reader.truncatedAt() > int64_t(in.n) + 8) __builtin_trap();
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string reader = [] {
    const char* r = std::getenv("SPINRADAR_FUZZ_READER");
    return std::string(r ? r : "png");
  }();
  const Input in{data, size};
  if (reader == "png") fuzzPng(in);
  else if (reader == "mulran") fuzzMulran(in);
  else if (reader == "radiate") fuzzRadiate(in);
  else if (reader == "csv") fuzzCsv(in);
  else if (reader == "capture") fuzzCapture(in);
  else __builtin_trap();  // a misspelt reader must not pass as a clean run
  return 0;
}
