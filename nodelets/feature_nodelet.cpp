// Feature nodelet: one polar scan in (spinradar/RadarScan on `scan`, or with input:=oxford_image
// the Oxford-layout sensor_msgs/Image of existing radar bags on `polar_image`); its keypoints
// with azimuth times and ORB descriptors out (spinradar/Features on `features`), plus the
// Cartesian scan with keypoints drawn (`debug_image`) while someone listens.
#include <memory>
#include <mutex>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <spinradar/FeatureNodeletConfig.h>

#include "spinradar/features/feature_extractor.hpp"
#include "spinradar_ros/conversions.hpp"
#include "spinradar_ros/params.hpp"
#include "spinradar_ros/validated_reconfigure.hpp"
#include "spinradar_ros/polar_scan_conversions.hpp"

namespace spinradar_ros {

class FeatureNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    loadParams(pnh, config_);
    config_.validate();  // a bad parameter fails the load, naming it
    extractor_ = std::make_unique<spinradar::FeatureExtractor>(config_.detector, config_.features);
    frame_id_ = pnh.param<std::string>("frame_id", "");  // "" = the scan's own frame_id
    publish_debug_image_ = pnh.param("publish_debug_image", true);
    const std::string input = pnh.param<std::string>("input", "polar_scan");
    const int queue = pnh.param("queue_size", 20);

    features_pub_ = nh.advertise<spinradar::Features>("features", 20);
    debug_pub_ = nh.advertise<sensor_msgs::Image>("debug_image", 1);
    reconfigure_ = std::make_unique<Reconfigure>(pnh, config_, mutex_, [this] {
      extractor_ = std::make_unique<spinradar::FeatureExtractor>(config_.detector, config_.features);
    });

    if (input == "polar_scan") {
      sub_ = nh.subscribe("scan", queue, &FeatureNodelet::onScan, this);
    } else if (input == "oxford_image") {
      range_resolution_ = pnh.param("range_resolution", 0.0438);  // the image does not carry it
      sub_ = nh.subscribe("polar_image", queue, &FeatureNodelet::onImage, this);
    } else {
      throw std::invalid_argument("parameter 'input' = '" + input +
                                  "' is not one of: polar_scan, oxford_image");
    }
    NODELET_INFO("detector '%s' on %s", config_.detector.detector.c_str(),
                 sub_.getTopic().c_str());
  }

  void onScan(const spinradar::RadarScanConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      fromMsg(*msg, scan_);
    } catch (const std::exception& e) {
      NODELET_ERROR("dropping scan at %.3f: %s", msg->header.stamp.toSec(), e.what());
      return;
    }
    process(msg->header);
  }

  void onImage(const sensor_msgs::ImageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      fromOxfordImage(*msg, scan_, range_resolution_);
    } catch (const std::exception& e) {
      NODELET_ERROR("dropping image at %.3f: %s", msg->header.stamp.toSec(), e.what());
      return;
    }
    process(msg->header);
  }

  void process(const std_msgs::Header& in) {
    extractor_->extract(scan_, frame_);
    const std::string& frame_id = frame_id_.empty() ? in.frame_id : frame_id_;
    auto out = boost::make_shared<spinradar::Features>();
    toMsg(frame_, scan_.lastStamp(), frame_id, *out);
    features_pub_.publish(out);  // zero-copy to the estimator in the same manager
    if (publish_debug_image_ && debug_pub_.getNumSubscribers() > 0) {
      auto image = boost::make_shared<sensor_msgs::Image>();
      toDebugImageMsg(extractor_->cartesianImage(), frame_, config_.features.cart_resolution,
                      out->header, *image);
      debug_pub_.publish(image);
    }
  }

  spinradar::PipelineConfig config_;  // detector and features are used
  std::unique_ptr<spinradar::FeatureExtractor> extractor_;
  spinradar::PolarScan scan_;
  spinradar::FeatureFrame frame_;
  double range_resolution_ = 0.0438;
  std::string frame_id_;
  bool publish_debug_image_ = true;
  std::mutex mutex_;  // callbacks and reconfiguration may run on different threads

  ros::Subscriber sub_;
  ros::Publisher features_pub_, debug_pub_;
  using Reconfigure = ValidatedReconfigure<spinradar::FeatureNodeletConfig, spinradar::PipelineConfig>;
  std::unique_ptr<Reconfigure> reconfigure_;
};

}  // namespace spinradar_ros

PLUGINLIB_EXPORT_CLASS(spinradar_ros::FeatureNodelet, nodelet::Nodelet)
