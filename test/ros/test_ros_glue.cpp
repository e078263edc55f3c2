// ROS glue without a master: dynamic_reconfigure entries generated from params.hpp, the
// generic reconfigure copy, and the message conversions.
#include <cmath>
#include <type_traits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <spinradar/EstimatorNodeletConfig.h>
#include <spinradar/FeatureNodeletConfig.h>

#include "spinradar/core/lie.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar_ros/conversions.hpp"
#include "spinradar_ros/params.hpp"

namespace {

using spinradar_ros::fromReconfigure;

/// Every field of `cfg` (except `skip`) has a dynamic_reconfigure entry with the same type,
/// default, range and a description "doc [unit]".
template <class DrConfig, class Config>
int expectEntries(const Config& cfg, const std::vector<std::string>& skip = {}) {
  const auto& descriptions = DrConfig::__getParamDescriptions__();
  const DrConfig def = DrConfig::__getDefault__(), lo = DrConfig::__getMin__(), hi = DrConfig::__getMax__();
  int found = 0;
  cfg.visit([&](const spinradar::ParamMeta& m, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (std::find(skip.begin(), skip.end(), m.name) != skip.end()) return;
    for (const auto& d : descriptions) {
      if (d->name != m.name) continue;
      ++found;
      boost::any a;
      d->getValue(def, a);
      EXPECT_EQ(boost::any_cast<T>(a), value) << m.name;
      const std::string doc = m.doc;
      EXPECT_EQ(d->description.find(doc.substr(0, doc.find('\''))), 0u) << m.name << ": " << d->description;
      if (m.unit[0]) {
        EXPECT_NE(d->description.find(std::string("[") + m.unit + "]"), std::string::npos) << m.name;
      }
      if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
        d->getValue(lo, a);
        EXPECT_DOUBLE_EQ(static_cast<double>(boost::any_cast<T>(a)), m.min) << m.name;
        d->getValue(hi, a);
        EXPECT_DOUBLE_EQ(static_cast<double>(boost::any_cast<T>(a)), m.max) << m.name;
      }
      return;
    }
    ADD_FAILURE() << "no dynamic_reconfigure entry for " << m.name;
  });
  return found;
}

TEST(ReconfigureEntries, FeatureNodeletCarriesDetectorAndFeatureParams) {
  spinradar::PipelineConfig c;
  const int n = expectEntries<spinradar::FeatureNodeletConfig>(c.detector) +
                expectEntries<spinradar::FeatureNodeletConfig>(c.features, {"nndr"});
  EXPECT_EQ(static_cast<size_t>(n), spinradar::FeatureNodeletConfig::__getParamDescriptions__().size());
}

TEST(ReconfigureEntries, EstimatorNodeletCarriesEstimatorParamsAndNndr) {
  spinradar::PipelineConfig c;
  int n = expectEntries<spinradar::EstimatorNodeletConfig>(c.estimator);
  for (const auto& d : spinradar::EstimatorNodeletConfig::__getParamDescriptions__()) n += d->name == "nndr";
  EXPECT_EQ(static_cast<size_t>(n), spinradar::EstimatorNodeletConfig::__getParamDescriptions__().size());
}

TEST(ReconfigureEntries, EstimatorIsAnEnumOfItsChoices) {
  const auto& d = spinradar::EstimatorNodeletConfig::__getDescriptionMessage__();
  bool seen = false;
  for (const auto& g : d.groups)
    for (const auto& p : g.parameters)
      if (p.name == "estimator") {
        seen = true;
        for (const char* c : {"rigid", "mc", "mc_doppler", "refined", "keyframe"})
          EXPECT_NE(p.edit_method.find(std::string("'") + c + "'"), std::string::npos) << c;
      }
  EXPECT_TRUE(seen);
}

TEST(Reconfigure, CopiesByNameAndRejectsInvalid) {
  spinradar::PipelineConfig cfg;
  auto dr = spinradar::FeatureNodeletConfig::__getDefault__();
  dr.zq = 4.5;
  dr.detector = "cfar";
  dr.max_range = 80.0;
  EXPECT_EQ(spinradar_ros::applyReconfigure(dr, cfg), "");
  EXPECT_EQ(cfg.detector.zq, 4.5);
  EXPECT_EQ(cfg.detector.detector, "cfar");
  EXPECT_EQ(cfg.detector.max_range, 80.0);
  EXPECT_EQ(cfg.estimator.estimator, spinradar::PipelineConfig{}.estimator.estimator);  // untouched
  dr.min_range = 90.0;  // >= max_range: validate() refuses, nothing is committed
  const std::string err = spinradar_ros::applyReconfigure(dr, cfg);
  EXPECT_NE(err.find("min_range"), std::string::npos) << err;
  EXPECT_EQ(cfg.detector.min_range, 2.5);
}

TEST(Conversions, FeaturesRoundTrip) {
  spinradar::FeatureFrame f;
  f.stamp_ns = 1700000000123456789LL;
  f.period_ns = 250000000;  // the rotation period goes along (dropped scans, issue 19)
  for (int i = 0; i < 5; ++i) {
    spinradar::Keypoint k;
    k.range = 10 + i;
    k.azimuth = 0.1 * i;
    k.x = k.range * std::cos(k.azimuth);
    k.y = -k.range * std::sin(k.azimuth);
    k.stamp_ns = f.stamp_ns + i * 625000;
    k.power = 50.f + i;
    k.azimuth_index = 4 * i;
    k.bin = 228.5f + i;
    f.keypoints.push_back(k);
  }
  f.descriptors = cv::Mat(5, 32, CV_8U);
  cv::randu(f.descriptors, 0, 255);
  spinradar::Features msg;
  spinradar_ros::toMsg(f, f.stamp_ns + 249000000, "radar", msg);
  EXPECT_EQ(msg.header.frame_id, "radar");
  EXPECT_EQ(msg.descriptor_size, 32u);
  EXPECT_EQ(spinradar_ros::toNs(msg.scan_end), f.stamp_ns + 249000000);
  spinradar::FeatureFrame back;
  spinradar_ros::fromMsg(msg, back);
  EXPECT_EQ(back.stamp_ns, f.stamp_ns);
  EXPECT_EQ(back.period_ns, f.period_ns);
  ASSERT_EQ(back.keypoints.size(), 5u);
  EXPECT_EQ(back.keypoints[3].stamp_ns, f.keypoints[3].stamp_ns);
  EXPECT_EQ(back.keypoints[3].bin, f.keypoints[3].bin);
  EXPECT_EQ(cv::norm(back.descriptors, f.descriptors, cv::NORM_L1), 0.0);
  msg.descriptors.pop_back();
  EXPECT_THROW(spinradar_ros::fromMsg(msg, back), std::runtime_error);
}

TEST(Conversions, OdometryInBaseFrameWithMounting) {
  // Radar 2 m ahead of the base, turned 90 deg left; the radar moves 1 m along its own x
  // while turning 0.1 rad: the base's motion is the conjugate, its twist the adjoint.
  spinradar_ros::OdometryFrames fr;
  fr.T_base_radar = spinradar::se2::fromXyYaw({2.0, 0.0, M_PI / 2});
  spinradar::OdometryResult r;
  r.ok = true;
  r.stamp_ns = 5'000'000'000LL;
  r.T_world_sensor = spinradar::se2::fromXyYaw({1.0, 0.0, 0.1});
  r.motion.velocity = Eigen::Vector3d(4.0, 0.0, 0.4);
  r.pose_cov = Eigen::Vector3d(0.01, 0.02, 0.001).asDiagonal();
  nav_msgs::Odometry o;
  spinradar_ros::toOdometryMsg(r, fr, o);
  const Eigen::Matrix3d T = fr.T_base_radar * r.T_world_sensor * spinradar::se2::inverse(fr.T_base_radar);
  EXPECT_NEAR(o.pose.pose.position.x, T(0, 2), 1e-12);
  EXPECT_NEAR(o.pose.pose.position.y, T(1, 2), 1e-12);
  EXPECT_NEAR(2 * std::atan2(o.pose.pose.orientation.z, o.pose.pose.orientation.w), 0.1, 1e-12);
  EXPECT_EQ(o.header.frame_id, "odom");
  EXPECT_EQ(o.child_frame_id, "base_link");
  // Base twist: v_b = C v_r + w [r_y, -r_x] = (0, 4) + 0.4 (0, -2) = (0, 3.2).
  EXPECT_NEAR(o.twist.twist.linear.x, 0.0, 1e-12);
  EXPECT_NEAR(o.twist.twist.linear.y, 3.2, 1e-12);
  EXPECT_NEAR(o.twist.twist.angular.z, 0.4, 1e-12);
  // Ad = [[0, -1, 0], [1, 0, -2], [0, 0, 1]]: x and y swap, the lever arm adds yaw variance
  // to the base's y; unobserved dims get the large variance.
  EXPECT_NEAR(o.pose.covariance[0], 0.02, 1e-12);
  EXPECT_NEAR(o.pose.covariance[7], 0.01 + 4 * 0.001, 1e-12);
  EXPECT_NEAR(o.pose.covariance[35], 0.001, 1e-12);
  EXPECT_EQ(o.pose.covariance[14], spinradar_ros::kUnobservedVariance);
  geometry_msgs::TransformStamped tf;
  spinradar_ros::toTfMsg(r, fr, tf);
  EXPECT_NEAR(tf.transform.translation.x, T(0, 2), 1e-12);
  EXPECT_EQ(tf.header.stamp.toNSec(), 5'000'000'000ULL);
}

TEST(Conversions, CloudCarriesIntensityAndTime) {
  std::vector<Eigen::Vector2d> pts{{1, 2}, {3, 4}};
  std::vector<spinradar::Keypoint> kps(2);
  kps[1].power = 7.f;
  kps[1].stamp_ns = 1'000'000'000LL + 100'000'000LL;
  std_msgs::Header h;
  h.stamp.fromNSec(1'000'000'000ULL);
  h.frame_id = "radar";
  sensor_msgs::PointCloud2 c;
  spinradar_ros::toCloudMsg(pts, kps, h, c);
  ASSERT_EQ(c.width, 2u);
  sensor_msgs::PointCloud2ConstIterator<float> x(c, "x"), i(c, "intensity"), t(c, "t");
  ++x, ++i, ++t;
  EXPECT_EQ(x[0], 3.f);
  EXPECT_EQ(x[1], 4.f);
  EXPECT_EQ(*i, 7.f);
  EXPECT_NEAR(*t, 0.1f, 1e-6);
}

}  // namespace
