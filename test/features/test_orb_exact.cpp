// The ORB describer's own path (blur once, 256 comparisons at precomputed offsets) gives byte for
// byte cv::ORB::compute's descriptors and drops the same keypoints: on Cartesian radar images,
// with keypoints on half pixels and at the borders, upright and oriented, for several patch sizes.
#include <gtest/gtest.h>

#include <random>

#include "support/feature_test_utils.hpp"
#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/orb_descriptors.hpp"

using namespace spinradar;
using spinradar::test::Target;

namespace {

/// Keypoints spread over the image (in metres), some exactly on half pixels and some within a
/// patch of the border, where ORB's edge filter decides by the rounded pixel.
std::vector<Keypoint> keypointsOver(const CartesianProjector& proj, unsigned seed) {
  std::mt19937 rng(seed);
  const double half_m = 0.5 * proj.width() * proj.resolution();
  std::uniform_real_distribution<double> xy(-half_m, half_m), pw(0.0, 50.0);
  std::vector<Keypoint> k(3000);
  for (size_t i = 0; i < k.size(); ++i) {
    k[i].x = xy(rng);
    k[i].y = xy(rng);
    if (i % 7 == 0) {  // a half pixel: cvRound's ties
      const cv::Point2f p = proj.toPixel(k[i].x, k[i].y);
      const cv::Point2d m = proj.toMetric({std::floor(p.x) + 0.5f, std::floor(p.y) + 0.5f});
      k[i].x = m.x;
      k[i].y = m.y;
    }
    k[i].power = static_cast<float>(pw(rng));
    k[i].azimuth_index = static_cast<int>(i);
  }
  return k;
}

}  // namespace

TEST(OrbExact, SameDescriptorsAndKeypointsAsOpenCv) {
  std::vector<Target> targets;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(5, 160), snr(15, 45);
  for (int i = 0; i < 400; ++i) targets.push_back({az(rng), r(rng), snr(rng)});
  const PolarScan scan = spinradar::test::syntheticScan(targets, 3);
  CartesianProjector proj;
  cv::Mat image;
  proj.render(scan, image);
  for (int patch : {21, 15, 33}) {
    for (bool oriented : {false, true}) {
      OrbDescriber fast(patch, oriented), opencv(patch, oriented);
      opencv.setUseOpenCv(true);
      std::vector<Keypoint> k1 = keypointsOver(proj, 11 + patch), k2 = k1;
      cv::Mat d1, d2;
      for (int round = 0; round < 2; ++round) {  // the second time on reused buffers
        k1 = k2 = keypointsOver(proj, 11 + patch + round);
        fast.describe(image, proj, k1, d1);
        opencv.describe(image, proj, k2, d2);
        const std::string what = "patch " + std::to_string(patch) + (oriented ? " oriented" : " upright");
        ASSERT_EQ(k1.size(), k2.size()) << what;
        ASSERT_GT(k1.size(), 2000u) << what;
        ASSERT_LT(k1.size(), 3000u) << what << ": some keypoints must fall off the edge";
        for (size_t i = 0; i < k1.size(); ++i) ASSERT_EQ(k1[i].azimuth_index, k2[i].azimuth_index) << what;
        ASSERT_EQ(d1.rows, d2.rows);
        ASSERT_EQ(d1.cols, 32);
        EXPECT_EQ(cv::norm(d1, d2, cv::NORM_HAMMING), 0) << what;
      }
    }
  }
}
