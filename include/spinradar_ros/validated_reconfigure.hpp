#pragma once
// A dynamic_reconfigure server whose updates are checked by the core Config::validate(): a
// rejected update is logged and the parameters actually in use are reported back to the client.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <dynamic_reconfigure/server.h>
#include <ros/console.h>

#include "spinradar_ros/params.hpp"

namespace spinradar_ros {

template <class DrConfig, class Config>
class ValidatedReconfigure {
 public:
  /// `on_change` runs (under `mutex`) after `cfg` took an accepted update.
  ValidatedReconfigure(ros::NodeHandle& pnh, Config& cfg, std::mutex& mutex,
                       std::function<void()> on_change)
      : server_(server_mutex_, pnh) {
    server_.setCallback([this, &cfg, &mutex, on_change](DrConfig& c, uint32_t) {
      std::lock_guard<std::mutex> lock(mutex);
      const std::string error = applyReconfigure(c, cfg);
      if (!error.empty()) {
        ROS_ERROR("rejected reconfiguration: %s", error.c_str());
        c = accepted_;
        return;
      }
      accepted_ = c;
      on_change();
    });
  }

 private:
  boost::recursive_mutex server_mutex_;
  dynamic_reconfigure::Server<DrConfig> server_;
  DrConfig accepted_ = DrConfig::__getDefault__();
};

}  // namespace spinradar_ros
