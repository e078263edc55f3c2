#pragma once
// The single definition of every Navtech driver parameter (nodelet ROS params, CLI options and
// the README table read this list). One entry per line: X(type, name, default, min, max, unit, doc).
#include <string>

#include "spinradar/core/param_macros.hpp"

// clang-format off
#define SPINRADAR_DRIVER_PARAMS(X) \
  X(std::string, input, "socket", 0, 0, "", "Source of azimuth data: socket, capture or sim") \
  X(std::string, host, "127.0.0.1", 0, 0, "", "Radar IP address (input socket)") \
  X(int, port, 6317, 1, 65535, "", "Radar TCP port (input socket)") \
  X(std::string, frame_id, "radar", 0, 0, "", "Frame id of published scans") \
  X(double, connect_timeout, 2.0, 0.01, 60.0, "s", "Give up one connection attempt after this long") \
  X(double, stall_timeout, 2.0, 0.05, 60.0, "s", "Reconnect when no byte arrives for this long") \
  X(double, backoff_min, 0.1, 0.001, 60.0, "s", "First delay before reconnecting; doubles per failure") \
  X(double, backoff_max, 5.0, 0.01, 600.0, "s", "Largest delay between reconnection attempts") \
  X(double, poll_timeout, 0.2, 0.001, 10.0, "s", "Longest wait of one poll (bounds shutdown time)") \
  X(std::string, time_source, "sensor", 0, 0, "", "Azimuth stamps: sensor, receive or smoothed (sensor mapped onto receive clock)") \
  X(std::string, time_byte_order, "auto", 0, 0, "", "Byte order of the sensor's seconds/nanoseconds: auto, little or big") \
  X(double, smoothing_window, 5.0, 0.1, 600.0, "s", "Window of the smoothed sensor-to-receive clock mapping") \
  X(double, time_jump_tolerance, 0.1, 0.001, 10.0, "s", "Sensor time off the rotation rate by more than this (clock step or gap) drops the rotation in progress and re-anchors the clock mapping") \
  X(bool, drop_partial, true, 0, 0, "", "Drop (true) or publish with invalid rows (false) a rotation joined mid-way") \
  X(double, min_valid_fraction, 0.5, 0.0, 1.0, "", "Drop rotations with fewer valid azimuths than this fraction") \
  X(double, fft16_divisor, 256.0, 1.0, 65536.0, "", "16-bit FFT value / divisor = 8-bit power of the core scan") \
  X(std::string, capture_file, "", 0, 0, "", "Raw TCP capture to replay (input capture)") \
  X(double, capture_rate, 0.0, 0.0, 1000.0, "x", "Replay speed of a capture: 1 = real time, 0 = as fast as possible") \
  X(std::string, record_file, "", 0, 0, "", "Also record the raw TCP stream to this capture file (input socket)") \
  X(std::string, sim_scene, "city", 0, 0, "", "Built-in simulator scene (input sim)") \
  X(double, sim_rate, 1.0, 0.0, 1000.0, "x", "Simulator speed: 1 = real time (stamps then follow the wall clock), 0 = as fast as possible with the simulator clock (input sim)") \
  X(bool, publish_image, false, 0, 0, "", "Also publish the Oxford-layout mono8 image (CFEAR, Boreas tools)")
// clang-format on

namespace spinradar {

struct DriverConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_DRIVER_PARAMS)
  void validate() const;  ///< throws std::invalid_argument naming the parameter
};

}  // namespace spinradar
