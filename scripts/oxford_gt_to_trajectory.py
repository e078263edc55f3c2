#!/usr/bin/env python3
"""Oxford Radar RobotCar gt/radar_odometry.csv -> trajectory CSV t,x,y,yaw (REP 103).

Each row of radar_odometry.csv is the SE(2) motion from destination_radar_timestamp to
source_radar_timestamp in the dataset's frame (x forward, y right, yaw clockwise). The rows are
chained from the first destination stamp (pose 0 = origin) exactly as
readOxfordRadarOdometry in src/evaluation/evaluation.cpp does, and converted to REP 103 by
conjugating with diag(1, -1). Stamps are microseconds in, seconds out.

Usage: oxford_gt_to_trajectory.py radar_odometry.csv out.csv
"""
import csv
import math
import sys


def compose(a, b):
    """Pose a then relative motion b, both (x, y, yaw)."""
    ax, ay, ayaw = a
    bx, by, byaw = b
    c, s = math.cos(ayaw), math.sin(ayaw)
    yaw = math.atan2(math.sin(ayaw + byaw), math.cos(ayaw + byaw))
    return (ax + c * bx - s * by, ay + s * bx + c * by, yaw)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    src_path, out_path = argv[1], argv[2]
    rows = []
    with open(src_path, newline="") as f:
        reader = csv.DictReader(f)
        need = {"x", "y", "yaw", "source_radar_timestamp", "destination_radar_timestamp"}
        missing = need - set(reader.fieldnames or [])
        if missing:
            sys.exit(f"{src_path}:1: not an Oxford radar_odometry.csv header (missing "
                     f"{', '.join(sorted(missing))})")
        for line_no, r in enumerate(reader, start=2):
            try:
                src = int(r["source_radar_timestamp"])
                dst = int(r["destination_radar_timestamp"])
                x, y, yaw = float(r["x"]), float(r["y"]), float(r["yaw"])
            except (TypeError, ValueError) as e:
                sys.exit(f"{src_path}:{line_no}: malformed number ({e})")
            if not all(math.isfinite(v) for v in (x, y, yaw)):
                sys.exit(f"{src_path}:{line_no}: non-finite value")
            if src <= dst:
                sys.exit(f"{src_path}:{line_no}: source_radar_timestamp is not after "
                         "destination_radar_timestamp")
            if rows and dst != rows[-1][1]:
                sys.exit(f"{src_path}:{line_no}: destination_radar_timestamp {dst} is not the "
                         f"previous row's source_radar_timestamp {rows[-1][1]}")
            rows.append((dst, src, x, y, yaw))
    if not rows:
        sys.exit(f"{src_path}: no relative poses after the header")
    pose = (0.0, 0.0, 0.0)
    out = [(rows[0][0], pose)]
    for _, src, x, y, yaw in rows:
        pose = compose(pose, (x, -y, -yaw))  # dataset frame -> REP 103
        out.append((src, pose))
    with open(out_path, "w", newline="") as f:
        f.write("t,x,y,yaw\n")
        for t_us, (x, y, yaw) in out:
            f.write(f"{t_us * 1e-6:.6f},{x:.6f},{y:.6f},{yaw:.6f}\n")


if __name__ == "__main__":
    main(sys.argv)
