#pragma once
// Ground-truth files of the public radar datasets, read into absolute poses (REP 103, seconds)
// for `spinradar eval`. Every reader throws std::runtime_error "<file>:<line>: <reason>".
#include <string>
#include <vector>

#include "spinradar/io/poses_io.hpp"

namespace spinradar {

/// Reads the Oxford Radar RobotCar `gt/radar_odometry.csv` into absolute poses, REP 103.
/// Each row is the motion between two radar scans: the pose of the source (later) scan in the
/// destination (earlier) scan's frame, in the dataset's x-forward, y-right, z-down frame (the
/// SDK's interpolate_vo_poses compounds abs_k = abs_{k-1} * rel_k). Converted to REP 103 by
/// flipping y and yaw. The first pose (identity) is stamped with the first row's
/// destination_radar_timestamp and pose k with row k's source_radar_timestamp (the scan file
/// names = first-azimuth stamps, the clock `spinradar odometry` writes), in seconds. Rows whose
/// destination is not the previous row's source break the chain: error naming file and line.
std::vector<PoseRecord> readOxfordRadarOdometry(const std::string& path);

/// Reads a Boreas pose file (`applanix/radar_poses.csv`, also lidar_poses.csv or
/// gps_post_process.csv): header GPSTime, easting, northing, ..., roll, pitch, heading, ...
/// As pyboreas: C_enu_sensor = roll(r) pitch(p) yaw(heading) with its passive elementary
/// rotations; the 2D pose is the sensor's x axis in the east-north plane, so the sensor frame's
/// own convention (radar: x forward, z down, roll ~ pi) needs no special case. GPSTime is
/// microseconds (radar_poses.csv: the scan file name) or seconds (values below 1e11).
std::vector<PoseRecord> readBoreasPoses(const std::string& path);

/// Reads MulRan `global_pose.csv`: no header, one pose a line: time in ns, then the 3x4
/// [R | t] of the vehicle body in the global frame, row-major (12 values). Yaw from R, x/y from
/// t. The body is the vehicle's, not the radar's: see withSensorPose.
std::vector<PoseRecord> readMulranGlobalPose(const std::string& path);

/// Any ground truth `spinradar eval` takes, told apart by its first line: an Oxford
/// radar_odometry.csv header, a Boreas GPSTime header, 13 bare numbers (MulRan global_pose),
/// or a t,x,y,yaw CSV.
std::vector<PoseRecord> readGroundTruth(const std::string& path);

/// Ground truth of a body frame -> the sensor's: T_w_sensor = T_w_body * T_body_sensor with
/// T_body_sensor = (x, y, yaw) in metres / radians. A lever arm matters for drift: 1.5 m ahead
/// of the body, a 90 degree turn moves the sensor's endpoint by 2 m against the body's.
std::vector<PoseRecord> withSensorPose(const std::vector<PoseRecord>& body, double x, double y,
                                       double yaw);

}  // namespace spinradar
