// The odometry command's scan prefetcher: loads and extracts the next scans on background
// threads while the main thread matches and estimates (cmd_odometry.cpp).
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include "spinradar/estimation/odometry.hpp"
#include "spinradar/features/cartesian_tables.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/io/scan_folder.hpp"

namespace spinradar::cli {

/// CPU time of the calling thread (ms): with the wall clock of a loaded machine, what each
/// thread of the pipeline costs.
inline double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

/// Loads a folder's scans on `workers` background threads, up to `depth` scans ahead of the
/// consumer, and extracts their features there too (Odometry::extractFeatures, which depends on
/// the scan and the config only), so that decoding and features of the next scans (about 80 %
/// of the CPU per scan) overlap matching and estimation of the current one. Scans are claimed
/// in order by whichever thread is free, the consumer included: while take() waits it loads and
/// extracts the next unclaimed scan itself, so with one loader the two threads share the work.
/// Each thread has its own extractor (working buffers), all sharing one set of read-only
/// Cartesian tables, built once from the first scan as with one thread: the other scans wait
/// for the first scan's features before extracting theirs. take() hands the scans out in
/// order; a scan that failed to load rethrows its error there, at its own index, as the
/// single-thread loop would. The scans and their features live in a fixed ring of depth + 1
/// slots, each filled again once the consumer release()s it: no allocation per scan after
/// warm-up.
class ScanPrefetcher {
 public:
  struct Loaded {
    PolarScan scan;
    double load_ms = 0;
    std::string error;  ///< why the scan could not be read ("" when it was)
    FeatureFrame frame;          ///< the scan's features (prefetcher only)
    StageTimes times;            ///< their detect / Cartesian / describe times
    std::string extract_error;   ///< extraction threw: the run stops there, as with one thread
    size_t ready = 0;            ///< scan index + 1 once filled (guarded by the mutex)
  };
  /// Loads scan i of `folder` into `l`, reusing its buffers, and times it.
  static void loadInto(const ScanFolder& folder, size_t i, Loaded& l) {
    const auto t0 = std::chrono::steady_clock::now();
    l.error.clear();
    try {
      folder.load(i, l.scan);
    } catch (const std::exception& e) {
      l.error = e.what();  // the consumer warns and skips it
    }
    l.load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  ScanPrefetcher(const ScanFolder& folder, size_t depth, size_t workers, const PipelineConfig& config)
      : folder_(folder), config_(config), workers_(std::max<size_t>(1, workers)),
        slots_(std::max(std::max<size_t>(1, depth), workers_) + 1) {
    extractors_.reserve(workers_ + 1);  // the last one: the consumer's
    for (size_t w = 0; w <= workers_; ++w)
      extractors_.emplace_back(config.detector, config.features,
                               w == 0 ? nullptr : extractors_.front().cartesianTables());
    cpu_ms_.assign(workers_, 0.0);
    threads_.reserve(workers_);
    for (size_t w = 0; w < workers_; ++w) threads_.emplace_back([this, w] { loop(w); });
    // The pixel geometry (the scan-independent half of the Cartesian tables, ~7 ms) is built
    // here while a loader reads and detects the first scan, instead of after it.
    extractors_.back().cartesianTables()->pixels();
  }
  ~ScanPrefetcher() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  /// CPU time of each loader thread (ms), complete once all scans were taken.
  std::vector<double> workerCpuMs() {
    std::lock_guard<std::mutex> lock(mutex_);
    return cpu_ms_;
  }
  /// The next scan in folder order and its load time (ms); `wait_ms` += time spent waiting
  /// (or filling scans itself). Valid until release(), which must be called before the next take().
  Loaded& take(double& wait_ms) {
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    Loaded& item = slots_[taken_ % slots_.size()];
    while (item.ready != taken_ + 1) {
      if (claimable()) {  // help rather than wait
        const size_t i = claimed_++;
        lock.unlock();
        fill(i, extractors_.back());
        lock.lock();
        continue;
      }
      cv_.wait(lock);
    }
    ++taken_;
    lock.unlock();
    wait_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return item;
  }
  /// Gives the slot of the last take() back to the loaders.
  void release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = taken_;
    }
    cv_.notify_all();
  }

 private:
  /// An unclaimed scan whose slot is free (mutex held).
  bool claimable() const { return claimed_ < folder_.size() && claimed_ < released_ + slots_.size(); }

  void loop(size_t w) {
    for (;;) {
      size_t i;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stop_ || claimed_ >= folder_.size() || claimable(); });
        if (stop_ || claimed_ >= folder_.size()) return;
        i = claimed_++;
      }
      fill(i, extractors_[w]);  // outside the lock: the consumer may work meanwhile
      std::lock_guard<std::mutex> lock(mutex_);
      cpu_ms_[w] = threadCpuMs();
    }
  }

  /// Loads scan i into its slot and extracts its features, then marks it ready.
  void fill(size_t i, FeatureExtractor& extractor) {
    Loaded& l = slots_[i % slots_.size()];
    loadInto(folder_, i, l);
    l.extract_error.clear();
    if (i > 0) {  // the tables come from the first scan, as with one thread (jitter is tolerated)
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return first_done_ || stop_; });
    }
    if (l.error.empty()) {
      try {
        Odometry::extractFeatures(config_, extractor, l.scan, l.frame, &l.times);
      } catch (const std::exception& e) {
        l.extract_error = e.what();
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      l.ready = i + 1;
      if (i == 0) first_done_ = true;
    }
    cv_.notify_all();
  }

  const ScanFolder& folder_;
  const PipelineConfig config_;
  const size_t workers_;
  std::vector<FeatureExtractor> extractors_;  ///< one per loader, then the consumer's
  std::vector<Loaded> slots_;
  std::mutex mutex_;
  std::condition_variable cv_;
  size_t claimed_ = 0;   ///< scans [0, claimed_) are being filled or are ready
  size_t taken_ = 0;     ///< handed to the consumer
  size_t released_ = 0;  ///< given back: their slots may be filled again
  bool stop_ = false;
  bool first_done_ = false;  ///< scan 0 is filled (its features built the Cartesian tables)
  std::vector<double> cpu_ms_;  ///< per loader, as of its last scan
  std::vector<std::thread> threads_;
};

}  // namespace spinradar::cli
