// Navtech driver nodelet: a shell around spinradar::navtech::NavtechDriver. A poll thread
// (started in onInit, joined in the destructor) publishes one spinradar/RadarScan per rotation
// on `scan`, optionally the Oxford-layout mono8 image on `polar_image`, and diagnostics (scan
// rate, dropped azimuths and scans, reconnects, stream errors, time anomalies) on /diagnostics,
// at a level that reflects the last few seconds (navtech::DriverHealth).
#include <atomic>
#include <memory>
#include <thread>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include "spinradar/driver/driver_health.hpp"
#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/sim/sim_radar_input.hpp"
#include "spinradar_ros/params.hpp"
#include "spinradar_ros/polar_scan_conversions.hpp"

namespace spinradar_ros {

using namespace spinradar::navtech;

class DriverNodelet : public nodelet::Nodelet {
 public:
  ~DriverNodelet() override {
    running_ = false;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    loadParams(getPrivateNodeHandle(), config_);
    config_.validate();  // throws std::invalid_argument naming the parameter
    std::unique_ptr<RadarInput> input;
    if (config_.input == "sim") {
      spinradar::sim::SimInputOptions o;
      o.rate = config_.sim_rate;
      o.wall_clock = config_.sim_rate > 0;  // real-time runs look like a live sensor
      input = spinradar::sim::makeSimInput(
          spinradar::sim::makeBuiltinSimulator(config_.sim_scene, spinradar::sim::PhysicsConfig{}), o);
    } else {
      input = makeInput(config_);
    }
    driver_ = std::make_unique<NavtechDriver>(config_, std::move(input));
    driver_->setLog([this](LogLevel level, const std::string& m) {
      switch (level) {
        case LogLevel::Debug: NODELET_DEBUG_STREAM(m); break;
        case LogLevel::Info: NODELET_INFO_STREAM(m); break;
        case LogLevel::Warn: NODELET_WARN_STREAM(m); break;
        case LogLevel::Error: NODELET_ERROR_STREAM(m); break;
      }
    });
    scan_pub_ = nh.advertise<spinradar::RadarScan>("scan", 4);
    if (config_.publish_image) image_pub_ = nh.advertise<sensor_msgs::Image>("polar_image", 4);

    updater_ = std::make_unique<diagnostic_updater::Updater>(nh, getPrivateNodeHandle(), getName());
    updater_->setHardwareID(driver_->input().describe());
    rate_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
        diagnostic_updater::FrequencyStatusParam(&min_hz_, &max_hz_, 0.1, 10));
    updater_->add(*rate_);
    updater_->add("Navtech driver", this, &DriverNodelet::diagnose);

    running_ = true;
    thread_ = std::thread([this] { poll(); });
  }

  void poll() {
    const auto timeout = std::chrono::milliseconds(int64_t(config_.poll_timeout * 1000));
    while (running_ && ros::ok()) {
      const InputStatus st = driver_->poll(scan_, timeout);
      if (st == InputStatus::Ok) publish();
      updater_->update();
      if (st == InputStatus::End) {
        NODELET_INFO_STREAM(driver_->input().describe() << ": end of input");
        break;
      }
      if (st == InputStatus::Error) {
        NODELET_ERROR_STREAM(driver_->input().describe() << ": unrecoverable input error, stopping");
        break;
      }
    }
  }

  void publish() {
    if (driver_->hasConfiguration()) {
      const double hz = driver_->configuration().rotationHz();
      min_hz_ = 0.9 * hz;
      max_hz_ = 1.1 * hz;
    }
    rate_->tick();
    // A fresh message per scan: nodelet subscribers may still hold the previous one.
    auto msg = boost::make_shared<spinradar::RadarScan>();
    toMsg(scan_, config_.frame_id, float(config_.fft16_divisor), *msg);
    if (image_pub_ && image_pub_.getNumSubscribers() > 0) {
      auto img = boost::make_shared<sensor_msgs::Image>();
      toOxfordImage(scan_.scan, msg->header, *img);
      image_pub_.publish(img);
    }
    scan_pub_.publish(msg);
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& s) {
    const DriverStats st = driver_->stats();
    const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::steady_clock::now().time_since_epoch()).count();
    const Health h = health_.update(st, driver_->hasConfiguration(), now);
    using diagnostic_msgs::DiagnosticStatus;
    s.summary(h.level == HealthLevel::Error  ? DiagnosticStatus::ERROR
              : h.level == HealthLevel::Warn ? DiagnosticStatus::WARN
                                             : DiagnosticStatus::OK,
              h.message);
    s.add("scans", st.scans);
    s.add("azimuths", st.azimuths);
    s.add("dropped scans", st.dropped_scans);
    s.add("partial rotations at connect", st.partial_scans);
    s.add("missing azimuths", st.missing_azimuths);
    s.add("duplicated azimuths", st.duplicated_azimuths);
    s.add("connects", st.input.connects);
    s.add("reconnects", st.input.connects > 0 ? st.input.connects - 1 : 0);
    s.add("disconnects", st.input.disconnects);
    s.add("failed connects", st.input.failed_connects);
    s.add("garbage bytes", st.input.stream.garbage_bytes);
    s.add("oversized headers", st.input.stream.oversized);
    s.add("truncated messages", st.input.stream.truncated);
    s.add("malformed messages", st.input.malformed);
    s.add("unknown message types", st.input.unknown_types);
    s.add("time anomalies", st.time_anomalies);
    s.add("last time anomaly", st.last_time_anomaly.empty() ? "none" : st.last_time_anomaly);
    s.add("implausible sensor times", st.implausible_times);
    s.add("time byte order", st.byte_order == TimeByteOrder::Big ? "big" : "little");
    s.add("time source", config_.time_source);
  }

  spinradar::DriverConfig config_;
  std::unique_ptr<NavtechDriver> driver_;
  AssembledScan scan_;
  ros::Publisher scan_pub_, image_pub_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> rate_;
  double min_hz_ = 3.6, max_hz_ = 4.4;
  DriverHealth health_;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace spinradar_ros

PLUGINLIB_EXPORT_CLASS(spinradar_ros::DriverNodelet, nodelet::Nodelet)
