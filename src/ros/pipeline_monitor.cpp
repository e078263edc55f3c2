// PipelineMonitor nodelet (spinradar/PipelineMonitor): loaded into the pipeline's manager for
// demos and measurements. Writes the odometry to a pose CSV (`spinradar eval` reads it) and
// measures, per scan: latency from the scan's last azimuth (Features.scan_end, meaningful when
// scan stamps are wall-clock time, i.e. a live sensor) and from the moment the scan message
// was published (any source, bag playback included) to the odometry message; and the
// manager process's CPU time per scan (driver + features + estimator). A JSON summary is
// rewritten after every scan so it survives any shutdown.
#include <ctime>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>

#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <spinradar/Features.h>
#include <spinradar/RadarScan.h>

#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/io/poses_io.hpp"
#include "spinradar_ros/conversions.hpp"

namespace spinradar_ros {
namespace {

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

double wallSeconds() { return ros::WallTime::now().toSec(); }

}  // namespace

class PipelineMonitor : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const std::string csv = pnh.param<std::string>("odom_csv", "");
    summary_path_ = pnh.param<std::string>("summary", "");
    if (!csv.empty()) writer_ = std::make_unique<spinradar::PoseCsvWriter>(csv, true, true);
    // Only the arrival time of each scan is used; subscribing with the publisher's own type
    // keeps the in-manager hand-over zero-copy.
    if (pnh.param<std::string>("input", "polar_scan") == "oxford_image")
      scan_sub_ = nh.subscribe<sensor_msgs::Image>(
          "polar_image", 100, [this](const sensor_msgs::ImageConstPtr&) { onScan(); });
    else
      scan_sub_ = nh.subscribe<spinradar::RadarScan>(
          "scan", 100, [this](const spinradar::RadarScanConstPtr&) { onScan(); });
    features_sub_ = nh.subscribe("features", 100, &PipelineMonitor::onFeatures, this);
    odom_sub_ = nh.subscribe("odom", 100, &PipelineMonitor::onOdom, this);
  }

  void onScan() {
    std::lock_guard<std::mutex> lock(mutex_);
    scan_arrivals_.push_back(wallSeconds());
    if (scan_arrivals_.size() > 1000) scan_arrivals_.pop_front();
  }

  void onFeatures(const spinradar::FeaturesConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    // The scan that produced these features is the oldest one still waiting.
    Pending p;
    p.scan_end = msg->scan_end.toSec();
    if (!scan_arrivals_.empty()) {
      p.scan_published = scan_arrivals_.front();
      scan_arrivals_.pop_front();
    }
    pending_[toNs(msg->header.stamp)] = p;
  }

  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    const double now = wallSeconds();
    const double cpu = processCpuSeconds();
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = pending_.find(toNs(msg->header.stamp));
    if (it != pending_.end()) {
      // Only meaningful when scans carry wall-clock stamps (a live sensor); skip otherwise.
      const double since_last_azimuth = now - it->second.scan_end;
      if (since_last_azimuth >= 0 && since_last_azimuth < 60) azimuth_latency_.push_back(since_last_azimuth);
      if (it->second.scan_published > 0) publish_latency_.push_back(now - it->second.scan_published);
      pending_.erase(pending_.begin(), std::next(it));
    }
    if (scans_ == 0) {
      first_cpu_ = cpu;
      first_wall_ = now;
    }
    ++scans_;
    last_cpu_ = cpu;
    last_wall_ = now;
    if (writer_) {
      const auto& p = msg->pose.pose;
      spinradar::PoseRecord r;
      r.t = msg->header.stamp.toSec();
      r.x = p.position.x;
      r.y = p.position.y;
      r.yaw = std::atan2(2 * (p.orientation.w * p.orientation.z + p.orientation.x * p.orientation.y),
                         1 - 2 * (p.orientation.y * p.orientation.y + p.orientation.z * p.orientation.z));
      r.vx = msg->twist.twist.linear.x;
      r.vy = msg->twist.twist.linear.y;
      r.wz = msg->twist.twist.angular.z;
      writer_->write(r);
    }
    writeSummary();
  }

  void writeSummary() const {
    if (summary_path_.empty()) return;
    const auto a = spinradar::errorStats(azimuth_latency_);
    const auto p = spinradar::errorStats(publish_latency_);
    const long n = scans_ - 1;  // CPU and rate over the intervals after the first scan
    std::ofstream out(summary_path_, std::ios::trunc);
    out << "{\"scans\": " << scans_ << ", \"scan_rate_hz\": "
        << (n > 0 ? n / (last_wall_ - first_wall_) : 0.0)
        << ", \"cpu_ms_per_scan\": " << (n > 0 ? 1e3 * (last_cpu_ - first_cpu_) / n : 0.0)
        << ", \"latency_last_azimuth_ms\": {\"mean\": " << 1e3 * a.mean
        << ", \"median\": " << 1e3 * a.median << ", \"max\": " << 1e3 * a.max
        << ", \"count\": " << azimuth_latency_.size() << "}"
        << ", \"latency_scan_message_ms\": {\"mean\": " << 1e3 * p.mean
        << ", \"median\": " << 1e3 * p.median << ", \"max\": " << 1e3 * p.max
        << ", \"count\": " << publish_latency_.size() << "}}\n";
  }

  struct Pending {
    double scan_end = 0, scan_published = 0;
  };
  std::mutex mutex_;
  std::unique_ptr<spinradar::PoseCsvWriter> writer_;
  std::string summary_path_;
  std::deque<double> scan_arrivals_;
  std::map<int64_t, Pending> pending_;
  std::vector<double> azimuth_latency_, publish_latency_;
  long scans_ = 0;
  double first_cpu_ = 0, last_cpu_ = 0, first_wall_ = 0, last_wall_ = 0;
  ros::Subscriber scan_sub_, features_sub_, odom_sub_;
};

}  // namespace spinradar_ros

PLUGINLIB_EXPORT_CLASS(spinradar_ros::PipelineMonitor, nodelet::Nodelet)
