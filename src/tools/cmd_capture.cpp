// `spinradar capture record|replay`: record the raw TCP stream of a Navtech radar (or of
// `spinradar serve`) to a capture file, and replay a capture through the driver into an
// Oxford-layout scan folder (radar/<first stamp us>.png + radar.timestamps).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli_checks.hpp"
#include "command.hpp"
#include "spinradar/core/safe_output.hpp"
#include "spinradar/driver/capture.hpp"
#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/io/scan_io.hpp"

namespace {

using namespace spinradar;
using namespace spinradar::navtech;

std::atomic<bool> g_stop{false};

/// Every driver parameter as --name (underscores become dashes), from the X-macro list.
void addDriverOptions(CLI::App& app, DriverConfig& c, std::initializer_list<const char*> only) {
  c.visit([&](const ParamMeta& m, auto& v) {
    if (only.size() && std::none_of(only.begin(), only.end(),
                                    [&](const char* n) { return std::string(n) == m.name; }))
      return;
    std::string flag = std::string("--") + m.name;
    std::replace(flag.begin(), flag.end(), '_', '-');
    app.add_option(flag, v, std::string(m.doc) + (m.unit[0] ? std::string(" [") + m.unit + "]" : ""))
        ->capture_default_str();
  });
}

void record(DriverConfig c, const std::string& out, int scans, double duration) {
  // Recorded under a temporary name and moved onto --out when recording stops (Ctrl-C
  // included); after an input error what was recorded is kept too (a live stream cannot be
  // recorded again).
  AtomicOutputFile file(out);
  c.input = "socket";
  c.record_file = file.tempPath();
  int n = 0;
  std::string error;
  {
    NavtechDriver d(c);
    std::signal(SIGINT, [](int) { g_stop = true; });
    std::signal(SIGTERM, [](int) { g_stop = true; });
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
    AssembledScan s;
    while (!g_stop && (scans <= 0 || n < scans) &&
           (duration <= 0 || std::chrono::steady_clock::now() < end)) {
      const InputStatus st = d.poll(s, std::chrono::milliseconds(200));
      if (st == InputStatus::Ok && ++n % 20 == 0) std::cerr << "\rcapture: " << n << " rotations" << std::flush;
      if (st == InputStatus::Error) {
        error = "capture: input error (see log)";
        break;
      }
    }
    const DriverStats st = d.stats();
    std::cerr << "\ncapture: " << n << " rotations (" << st.azimuths << " azimuths, "
              << st.missing_azimuths << " missing, " << st.input.disconnects << " disconnects) -> "
              << out << std::endl;
  }  // the driver closes the capture file
  if (!std::filesystem::exists(file.tempPath()))
    throw std::runtime_error(out + ": nothing recorded (no connection to " + c.host + ":" +
                             std::to_string(c.port) + "?)" + (error.empty() ? "" : "; " + error));
  file.commit();
  if (!error.empty())
    throw std::runtime_error(error + "; the " + std::to_string(n) + " rotations recorded before it are in " + out);
}

/// Where the capture was cut short (-1: it ends cleanly between records).
int64_t truncationOffset(const std::string& path) {
  CaptureReader reader(path);
  CaptureReader::Record r;
  while (reader.next(r)) {
  }
  return reader.truncatedAt();
}

void replay(DriverConfig c, const std::string& in, const std::string& out_dir, int max_scans,
            bool force) {
  namespace fs = std::filesystem;
  refuseOutputOverInput({out_dir, "--out"}, {{in, "--in"}}, true);
  c.input = "capture";
  c.capture_file = in;
  NavtechDriver d(c);
  // Written aside and moved into place when complete: a failed replay leaves nothing.
  AtomicOutputFolder folder(out_dir, force);
  const std::string dir = folder.tempPath();
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "radar", ec);
  if (ec) throw std::runtime_error(dir + ": cannot create folder: " + ec.message());
  std::ofstream ts((fs::path(dir) / "radar.timestamps").string());
  if (!ts) throw std::runtime_error(out_dir + "/radar.timestamps: cannot write");
  AssembledScan s;
  int n = 0;
  for (;;) {
    const InputStatus st = d.poll(s, std::chrono::milliseconds(1000));
    if (st == InputStatus::End) break;
    if (st == InputStatus::Error) throw std::runtime_error(in + ": replay failed (see log)");
    if (st != InputStatus::Ok) continue;
    const int64_t ns = s.scan.firstStamp();
    const int64_t us = ns >= 0 ? ns / 1000 : -((-ns + 999) / 1000);
    saveOxfordPng(s.scan, (fs::path(dir) / "radar" / (std::to_string(us) + ".png")).string());
    ts << us << " 1\n";
    if (++n % 20 == 0) std::cerr << "\rreplay: " << n << " rotations" << std::flush;
    if (max_scans > 0 && n >= max_scans) break;
  }
  ts.close();
  if (!ts) throw std::runtime_error(out_dir + "/radar.timestamps: write failed");
  const DriverStats st = d.stats();
  const bool stopped_early = max_scans > 0 && n >= max_scans;
  const int64_t cut = stopped_early ? -1 : truncationOffset(in);
  const std::string cut_text =
      cut < 0 ? std::string()
              : in + ": capture cut short at byte " + std::to_string(cut) +
                    " (a record ends past the end of the file)";
  if (n == 0)
    throw std::runtime_error(in + ": no complete rotation in the capture (" +
                             std::to_string(st.azimuths) + " azimuths read" +
                             (cut >= 0 ? "; cut short at byte " + std::to_string(cut) : "") +
                             "); nothing written");
  folder.commit();
  std::cerr << "\nreplay: " << n << " rotations -> " << out_dir << " (" << st.dropped_scans
            << " dropped, " << st.missing_azimuths << " missing azimuths, "
            << st.input.stream.garbage_bytes << " garbage bytes)" << std::endl;
  if (cut >= 0)
    std::cerr << "warning: " << cut_text << ": the rotation in progress there is lost "
              << "(1 rotation; " << n << " complete rotations kept)" << std::endl;
}

}  // namespace

SPINRADAR_COMMAND("capture", "Record a Navtech TCP stream to a capture file, or replay one into a scan folder",
                  [](CLI::App& app) {
                    app.require_subcommand(1);
                    auto* rec = app.add_subcommand("record", "Connect to a radar and record its raw stream");
                    auto rc = std::make_shared<DriverConfig>();
                    auto out = std::make_shared<std::string>();
                    auto scans = std::make_shared<int>(0);
                    auto duration = std::make_shared<double>(0.0);
                    rec->add_option("--out", *out, "Capture file to write")->required();
                    rec->add_option("--scans", *scans, "Stop after this many rotations (0 = no limit)")
                        ->check(cli::atLeast(0));
                    rec->add_option("--duration", *duration, "Stop after this many seconds (0 = no limit)")
                        ->check(cli::atLeast(0));
                    addDriverOptions(*rec, *rc, {"host", "port", "connect_timeout", "stall_timeout",
                                                 "backoff_min", "backoff_max", "time_byte_order"});
                    rec->callback([=] { record(*rc, *out, *scans, *duration); });

                    auto* rep = app.add_subcommand("replay", "Replay a capture through the driver into an Oxford-layout folder");
                    auto pc = std::make_shared<DriverConfig>();
                    auto in = std::make_shared<std::string>();
                    auto dir = std::make_shared<std::string>();
                    auto max_scans = std::make_shared<int>(0);
                    auto force = std::make_shared<bool>(false);
                    rep->add_option("--in", *in, "Capture file")->required()->check(CLI::ExistingFile);
                    rep->add_option("--out", *dir, "Output folder (radar/*.png, radar.timestamps); new or empty")->required();
                    rep->add_flag("--force", *force, "Write into a non-empty --out folder: its old scans are removed first");
                    rep->add_option("--scans", *max_scans, "Stop after this many rotations (0 = all)")
                        ->check(cli::atLeast(0));
                    addDriverOptions(*rep, *pc, {"capture_rate", "time_source", "time_byte_order",
                                                 "smoothing_window", "drop_partial",
                                                 "min_valid_fraction", "fft16_divisor"});
                    rep->callback([=] { replay(*pc, *in, *dir, *max_scans, *force); });
                  });
