// `spinradar chirp-doppler`: Doppler inside single scans of a radar with alternating up/down
// chirps (Boreas-RT): detection, beta*|v|, heading, and |v| given beta or beta given |v|.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "command.hpp"
#include "spinradar/core/safe_output.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"
#include "spinradar/diagnose/chirp_doppler.hpp"

namespace {

using namespace spinradar;
namespace fs = std::filesystem;

struct ChirpDopplerArgs {
  std::string input, json, format = "auto";
  double beta = 0, speed = 0;
  double range_resolution = 0;  // 0: the format's own
  double range_offset = 1e9;    // 1e9: the format's own
  int first = 0, max_scans = 20;
  diagnose::ChirpDopplerOptions opt;
};

PolarScan loadFile(const ChirpDopplerArgs& a) {
  std::string ext = fs::path(a.input).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  const ScanFormat f = parseScanFormat(a.format);
  const bool have_res = a.range_resolution > 0, have_off = a.range_offset < 1e8;
  PolarScan s;
  if (f == ScanFormat::MulRan || (f == ScanFormat::Auto && ext == ".csv")) {
    s = loadMulranCsv(a.input);
  } else if (f == ScanFormat::Oxford) {
    s = loadOxfordPng(a.input);
  } else if (f == ScanFormat::Boreas || (f == ScanFormat::Auto && ext == ".png")) {
    // Boreas first: it reads the chirp column; other widths are Oxford-layout PNGs (simulator).
    try {
      s = loadBoreasPng(a.input);
    } catch (const std::runtime_error&) {
      if (f == ScanFormat::Boreas) throw;
      s = loadOxfordPng(a.input);
    }
  } else {
    throw std::runtime_error(a.input + ": a single scan must be a .png (Oxford/Boreas layout) or a MulRan .csv; "
                             "pass a folder for RADIATE");
  }
  if (have_res) s.range_resolution = a.range_resolution;
  if (have_off) s.range_offset = a.range_offset;
  return s;
}

void runChirpDoppler(ChirpDopplerArgs& a) {
  if (a.beta < 0 || a.speed < 0) throw std::invalid_argument("--beta and --speed must be > 0");
  if (a.beta > 0 && a.speed > 0) throw std::invalid_argument("give --beta or --speed, not both");
  if (a.beta > 0) a.opt.beta = a.beta;
  if (a.speed > 0) a.opt.speed = a.speed;
  if (!fs::exists(a.input)) throw std::runtime_error(a.input + ": no such file or folder");
  if (!(a.opt.min_range < a.opt.max_range))
    throw std::invalid_argument("--min-range " + readableNumber(a.opt.min_range) +
                                " m is not below --max-range " + readableNumber(a.opt.max_range) + " m");
  refuseOutputOverInput({a.json, "--json"}, {{a.input, "--input"}}, false);

  std::vector<std::pair<std::string, PolarScan>> scans;
  if (fs::is_directory(a.input)) {
    ScanFolderOptions fo;
    if (a.range_resolution > 0) fo.range_resolution = a.range_resolution;
    if (a.range_offset < 1e8) fo.range_offset = a.range_offset;
    ScanFolder folder(a.input, parseScanFormat(a.format), fo);
    if (folder.empty()) throw std::runtime_error(a.input + ": no scans found");
    if (a.first < 0 || size_t(a.first) >= folder.size())
      throw std::invalid_argument("--first " + std::to_string(a.first) + " but " + a.input + " holds " +
                                  std::to_string(folder.size()) + " scans");
    const size_t end = std::min(folder.size(), size_t(a.first) + size_t(std::max(1, a.max_scans)));
    for (size_t i = size_t(a.first); i < end; ++i) scans.emplace_back(folder.path(i), folder.load(i));
  } else {
    scans.emplace_back(a.input, loadFile(a));
  }

  nlohmann::json arr = nlohmann::json::array();
  std::vector<double> speeds, betas, amps;
  int detected = 0;
  for (auto& [path, scan] : scans) {
    const auto r = diagnose::estimateChirpDoppler(scan, a.opt);
    std::cout << fs::path(path).filename().string() << ": " << r.verdict << " [rows " << r.rows_used << "/"
              << r.rows_total << ", residual " << std::fixed << std::setprecision(3) << r.fit.residual_rms
              << " m]\n";
    nlohmann::json j = r.toJson();
    j["file"] = path;
    arr.push_back(j);
    if (r.detected) {
      ++detected;
      amps.push_back(r.beta_v);
      if (r.speed) speeds.push_back(*r.speed);
      if (r.beta) betas.push_back(*r.beta);
    }
  }
  auto med = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  nlohmann::json out;
  if (scans.size() == 1) {
    out = arr[0];
  } else {
    out = {{"scans", arr}, {"scans_detected", detected}, {"scans_total", scans.size()}};
    if (!amps.empty()) out["median_beta_v_m"] = med(amps);
    if (!speeds.empty()) out["median_speed_mps"] = med(speeds);
    if (!betas.empty()) out["median_beta_s"] = med(betas);
    std::cout << detected << "/" << scans.size() << " scans with alternating-chirp Doppler";
    if (!speeds.empty()) std::cout << ", median |v| " << med(speeds) << " m/s";
    if (!betas.empty()) std::cout << ", median beta " << std::setprecision(4) << med(betas) << " s";
    std::cout << "\n";
  }
  if (!a.json.empty()) {
    if (a.json == "-") {
      std::cout << out.dump(2) << "\n";
    } else {
      AtomicOutputFile f(a.json);
      f.stream() << out.dump(2) << "\n";
      f.commit();
    }
  }
}

}  // namespace

SPINRADAR_COMMAND(
    "chirp-doppler",
    "Doppler within single scans of alternating up/down chirps (Boreas-RT): detect, |v| or beta",
    [](CLI::App& app) {
      auto a = std::make_shared<ChirpDopplerArgs>();
      app.add_option("--input", a->input, "Scan file (.png Oxford/Boreas layout, MulRan .csv) or folder")
          ->required();
      app.add_option("--beta", a->beta, "Known beta = f_t / (df/dt) in s (Boreas-RT ~0.050): gives the velocity");
      app.add_option("--speed", a->speed, "Known speed in m/s: gives beta");
      app.add_option("--json", a->json, "Write the result as JSON to this file ('-' = stdout)");
      app.add_option("--format", a->format, "auto, oxford, boreas, mulran, radiate")->capture_default_str();
      app.add_option("--range-resolution", a->range_resolution, "m per bin (default: the format's own)")
          ->check(cli::positive());
      app.add_option("--range-offset", a->range_offset, "m added to every range (default: the format's own)");
      app.add_option("--first", a->first, "Folder: first scan index")
          ->capture_default_str()
          ->check(cli::atLeast(0));
      app.add_option("--max-scans", a->max_scans, "Folder: scans to analyse")
          ->capture_default_str()
          ->check(cli::atLeast(1));
      app.add_option("--min-range", a->opt.min_range, "m: closer bins (leakage) are ignored")
          ->capture_default_str()
          ->check(cli::atLeast(0));
      app.add_option("--max-range", a->opt.max_range, "m: farther bins are ignored")
          ->check(cli::positive());
      app.add_option("--max-shift", a->opt.max_shift, "m: largest range shift between chirps searched")
          ->capture_default_str()
          ->check(cli::positive());
      app.add_option("--alpha", a->opt.alpha, "False-alarm probability of the detection test")
          ->capture_default_str()
          ->check(cli::inRange(1e-300, 0.5));
      app.callback([a] { runChirpDoppler(*a); });
    });
