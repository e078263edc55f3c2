#pragma once
// Core PolarScan <-> spinradar/RadarScan message, and <-> the Oxford-layout mono8
// sensor_msgs/Image that CFEAR, the Boreas tools and other radar odometry codes read (rows =
// azimuths; columns 0-7 int64 LE microsecond stamp, 8-9 uint16 LE encoder, 10 valid byte 255/0,
// then the bins). The message is called RadarScan: a message PolarScan would generate a C++
// type spinradar::PolarScan clashing with the core struct.
#include <string>

#include <sensor_msgs/Image.h>
#include <spinradar/RadarScan.h>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/driver/scan_assembler.hpp"

namespace spinradar_ros {

/// Core scan -> message with 8-bit data. header.stamp = first valid azimuth's stamp.
void toMsg(const spinradar::PolarScan& scan, const std::string& frame_id, float rotation_hz,
           spinradar::RadarScan& msg);
/// Driver output -> message: 16-bit data at full precision when the sensor sent it (data8 then
/// empty), the rotation's counters and configuration. Buffers of `msg` are reused.
void toMsg(const spinradar::navtech::AssembledScan& scan, const std::string& frame_id,
           float fft16_divisor, spinradar::RadarScan& msg);
/// Message -> core scan (16-bit data mapped with msg.fft16_divisor, 256 when unset). Throws
/// std::runtime_error naming the field when the array sizes do not match azimuths x bins.
void fromMsg(const spinradar::RadarScan& msg, spinradar::PolarScan& scan);

/// Core scan -> Oxford-layout mono8 image (header given; encoding "mono8", step = width).
void toOxfordImage(const spinradar::PolarScan& scan, const std_msgs::Header& header,
                   sensor_msgs::Image& image);
/// Oxford-layout image -> core scan. The image carries no range resolution: pass it (Oxford
/// SDK 0.0432, CIR204-H 0.0438, early Boreas 0.0596). Throws std::runtime_error on a wrong
/// encoding or width.
void fromOxfordImage(const sensor_msgs::Image& image, spinradar::PolarScan& scan,
                     double range_resolution = 0.0438, double range_offset = 0.0);

}  // namespace spinradar_ros
