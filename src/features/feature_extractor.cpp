#include "spinradar/features/feature_extractor.hpp"

#include <chrono>

#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/detector.hpp"
#include "spinradar/features/orb_descriptors.hpp"

namespace spinradar {

namespace {
CartesianProjector makeProjector(const FeatureConfig& f, std::shared_ptr<CartesianTableCache> tables) {
  if (tables && tables->resolution() == f.cart_resolution && tables->width() == f.cart_pixel_width)
    return CartesianProjector(std::move(tables));
  return CartesianProjector(f.cart_resolution, f.cart_pixel_width);
}
}  // namespace

struct FeatureExtractor::Impl {
  Impl(const DetectorConfig& d, const FeatureConfig& f, std::shared_ptr<CartesianTableCache> tables)
      : detector_config(d), detector(d), projector(makeProjector(f, std::move(tables))),
        orb(f.orb_patch_size), features(f) {}
  DetectorConfig detector_config;
  Detector detector;
  CartesianProjector projector;
  OrbDescriber orb;
  FeatureConfig features;
  cv::Mat cart;
  std::vector<float> scratch;
};

FeatureExtractor::FeatureExtractor(const DetectorConfig& detector, const FeatureConfig& features)
    : FeatureExtractor(detector, features, nullptr) {}

FeatureExtractor::FeatureExtractor(const DetectorConfig& detector, const FeatureConfig& features,
                                   std::shared_ptr<CartesianTableCache> tables) {
  detector.validate();
  features.validate();
  impl_ = std::make_unique<Impl>(detector, features, std::move(tables));
}

FeatureExtractor::~FeatureExtractor() = default;
FeatureExtractor::FeatureExtractor(FeatureExtractor&&) noexcept = default;
FeatureExtractor& FeatureExtractor::operator=(FeatureExtractor&&) noexcept = default;

void FeatureExtractor::extract(const PolarScan& scan, FeatureFrame& out, StageTimes* times) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  Impl& m = *impl_;
  out.stamp_ns = 0;
  for (int a = 0; a < scan.azimuths && a < static_cast<int>(scan.stamp_ns.size()); ++a)
    if (scan.valid.size() != scan.stamp_ns.size() || scan.valid[a]) {
      out.stamp_ns = scan.stamp_ns[a];
      break;
    }
  out.period_ns = rotationPeriodNs(scan);
  const auto t0 = Clock::now();
  m.detector.detect(scan, out.keypoints);
  const auto t1 = Clock::now();
  if (scan.empty()) {
    m.cart.create(m.features.cart_pixel_width, m.features.cart_pixel_width, CV_8UC1);
    m.cart.setTo(0);
  } else {
    m.projector.render(scan, m.cart, m.detector_config.range_offset);
  }
  const auto t2 = Clock::now();
  keepStrongest(out.keypoints, m.features.max_keypoints, m.scratch);
  m.orb.describe(m.cart, m.projector, out.keypoints, out.descriptors);
  const auto t3 = Clock::now();
  if (times) {
    times->detect_ms = ms(t0, t1);
    times->cartesian_ms = ms(t1, t2);
    times->describe_ms = ms(t2, t3);
  }
}

const cv::Mat& FeatureExtractor::cartesianImage() const { return impl_->cart; }

const std::shared_ptr<CartesianTableCache>& FeatureExtractor::cartesianTables() const {
  return impl_->projector.tables();
}

void FeatureExtractor::setAzimuthPeaks(bool on) {
  impl_->detector_config.azimuth_peaks = on;
  impl_->detector.setAzimuthPeaks(on);
}

}  // namespace spinradar
