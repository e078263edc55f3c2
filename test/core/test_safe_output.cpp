// Outputs that lose nothing (temporary file or folder renamed when complete, inputs never
// overwritten) and the one checked integer conversion.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "support/temp_dir.hpp"
#include "spinradar/core/checked_int.hpp"
#include "spinradar/core/param_check.hpp"
#include "spinradar/core/safe_output.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

using spinradar::test::TempDir;

namespace {

std::string readAll(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(AtomicOutputFile, ReplacesOnlyWhenCommittedAndLeavesNoTemporary) {
  TempDir d;
  std::ofstream(d.file("out.csv")) << "old\n";
  {
    AtomicOutputFile f(d.file("out.csv"));
    EXPECT_NE(f.tempPath(), f.path());
    EXPECT_EQ(fs::path(f.tempPath()).parent_path(), d.path);  // same folder: atomic rename
    EXPECT_EQ(fs::path(f.tempPath()).extension(), ".csv");    // encoders chosen by extension
    f.stream() << "half";
    // destroyed without commit: a failed run
  }
  EXPECT_EQ(readAll(d.file("out.csv")), "old\n");
  EXPECT_EQ(d.entries(), 1u);
  {
    AtomicOutputFile f(d.file("out.csv"));
    f.stream() << "new\n";
    f.commit();
  }
  EXPECT_EQ(readAll(d.file("out.csv")), "new\n");
  EXPECT_EQ(d.entries(), 1u);
  EXPECT_NE(errorOf([&] { AtomicOutputFile f(d.file("no/such/dir/x.csv")); f.stream(); }).find("x.csv: cannot open"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { AtomicOutputFile f(d.path.string()); }).find("is a folder"), std::string::npos);
}

TEST(AtomicOutputFolder, RefusesNonEmptyFoldersAndReplacesOldScansWithForce) {
  TempDir d;
  const std::string rec = d.file("rec");
  fs::create_directories(rec + "/radar");
  std::ofstream(rec + "/radar/1.png") << "old scan";
  std::ofstream(rec + "/radar.timestamps") << "1 1\n";
  std::ofstream(rec + "/notes.txt") << "mine";
  const std::string e = errorOf([&] { AtomicOutputFolder f(rec, false); });
  EXPECT_NE(e.find(rec + ": folder is not empty"), std::string::npos) << e;
  EXPECT_NE(e.find("--force"), std::string::npos) << e;
  {
    AtomicOutputFolder f(rec, true);
    fs::create_directories(f.tempPath() + "/radar");
    std::ofstream(f.tempPath() + "/radar/2.png") << "new scan";
    // not committed: the old recording stays whole
  }
  EXPECT_TRUE(fs::exists(rec + "/radar/1.png"));
  EXPECT_EQ(d.entries(), 1u);  // no temporary folder left
  {
    AtomicOutputFolder f(rec, true);
    fs::create_directories(f.tempPath() + "/radar");
    std::ofstream(f.tempPath() + "/radar/2.png") << "new scan";
    std::ofstream(f.tempPath() + "/radar.timestamps") << "2 1\n";
    f.commit();
  }
  EXPECT_FALSE(fs::exists(rec + "/radar/1.png"));  // old scans removed, not mixed in
  EXPECT_TRUE(fs::exists(rec + "/radar/2.png"));
  EXPECT_EQ(readAll(rec + "/radar.timestamps"), "2 1\n");
  EXPECT_EQ(readAll(rec + "/notes.txt"), "mine");
  EXPECT_EQ(d.entries(), 1u);
  // A new folder appears only when complete.
  {
    AtomicOutputFolder f(d.file("fresh"), false);
    std::ofstream(f.tempPath() + "/a.txt") << "a";
    EXPECT_FALSE(fs::exists(d.file("fresh")));
    f.commit();
  }
  EXPECT_EQ(readAll(d.file("fresh/a.txt")), "a");
}

TEST(RefuseOutputOverInput, SameFileLinksAndFoldersHoldingInputs) {
  TempDir d;
  std::ofstream(d.file("scan.png")) << "x";
  fs::create_symlink(d.file("scan.png"), d.file("link.png"));
  const std::vector<NamedPath> in{{d.file("scan.png"), "--input"}};
  EXPECT_NE(errorOf([&] { refuseOutputOverInput({d.file("scan.png"), "--out"}, in); })
                .find("the output (--out) is the same file as --input"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { refuseOutputOverInput({d.file("link.png"), "--out"}, in); }),
            "(no error)");
  EXPECT_NE(errorOf([&] { refuseOutputOverInput({d.path.string() + "/./scan.png", "--out"}, in); }),
            "(no error)");
  EXPECT_NE(errorOf([&] { refuseOutputOverInput({d.path.string(), "--out"}, in, true); })
                .find("holds an input"),
            std::string::npos);
  EXPECT_EQ(errorOf([&] { refuseOutputOverInput({d.file("other.csv"), "--out"}, in); }), "(no error)");
}

TEST(CheckedInt, ParsesOnlyWhatFitsAndNamesOverflow) {
  int64_t v = 0;
  EXPECT_TRUE(parseInt64("9223372036854775807", v));
  EXPECT_EQ(v, std::numeric_limits<int64_t>::max());
  EXPECT_TRUE(parseInt64("-9223372036854775808", v));
  EXPECT_EQ(v, std::numeric_limits<int64_t>::min());
  EXPECT_FALSE(parseInt64("9223372036854775808", v));
  EXPECT_FALSE(parseInt64("99999999999999999999", v));
  EXPECT_FALSE(parseInt64("", v));
  EXPECT_FALSE(parseInt64("12a", v));
  EXPECT_FALSE(parseInt64("-", v));
  EXPECT_EQ(mulChecked(1547131046353776, 1000, "x"), 1547131046353776000);
  EXPECT_NE(errorOf([] { mulChecked(99999999999999999, 1000, "f.png: stamp"); })
                .find("f.png: stamp: 99999999999999999 x 1000 does not fit in 64 bits"),
            std::string::npos);
  EXPECT_THROW(addChecked(std::numeric_limits<int64_t>::max(), 1, "x"), std::runtime_error);
  EXPECT_THROW(roundToInt64Checked(1e19, "x"), std::runtime_error);
  EXPECT_THROW(roundToInt64Checked(std::nan(""), "x"), std::runtime_error);
  EXPECT_EQ(roundToInt64Checked(-2.6, "x"), -3);
  EXPECT_TRUE(parseSecondsToNs("1574859771.744660272", v));
  EXPECT_EQ(v, 1574859771744660272);
  EXPECT_TRUE(parseSecondsToNs("1.5", v));
  EXPECT_EQ(v, 1500000000);
  EXPECT_FALSE(parseSecondsToNs("9223372037.0", v));  // past 2^63 ns
  EXPECT_FALSE(parseSecondsToNs("1.5e3", v));
}

TEST(ParamCheck, RejectsNanAndPrintsRangesReadably) {
  const ParamMeta m{"zq", "", "", 0.0, 1e300};
  EXPECT_NE(errorOf([&] { checkParamValue(std::nan(""), m, "detector"); }).find("'zq' = nan is not a finite number"),
            std::string::npos);
  EXPECT_THROW(checkParamValue(HUGE_VAL, m, "detector"), std::invalid_argument);
  const std::string e = errorOf([&] { checkParamValue(-1, {"threads", "", "", 0, 2147483647}, "cli"); });
  EXPECT_NE(e.find("'threads' = -1 is outside [0, 2147483647]"), std::string::npos) << e;
  EXPECT_EQ(readableNumber(std::numeric_limits<double>::max()), "max");
  EXPECT_EQ(readableNumber(0.0438), "0.0438");
  EXPECT_NO_THROW(checkParamValue(0.5, m, "detector"));
}
