#!/usr/bin/env python3
"""Per-row view of the Cen2018 detector on Oxford polar PNG folders (docs/diagnose_cen2018.md).

Usage: scripts/cen2018_rows.py FOLDER [FOLDER ...]   (each FOLDER/*.png or FOLDER/radar/*.png)
Needs numpy and PIL (Debian: python3-numpy python3-pil). Prints per folder: Cen2018 keypoints per
scan by band (the detector of src/features/detector.cpp re-implemented: row mean and noise from
the samples below it over the whole row, Gaussian sigma 17 bins, zq 3, one keypoint per run), the
row statistics the threshold is drawn from, the code histogram and median per band, and the rows
grouped by the range of their first strong hit (>= 60 counts): mean count beyond 50 m and
keypoints per row.

Why: Cen2018's threshold is a statistic of the whole row, so its counts per band depend on what
the row holds outside the band (the far part, behind a near wall); these figures show where a
simulated scan's keypoints come from.
"""
import glob
import os
import sys

import numpy as np
from PIL import Image

META = 11  # Oxford polar PNG: 8 bytes stamp, 2 bytes azimuth, 1 byte valid, then the bins
RES = 0.0438  # m per bin (CTS350-X); the PNGs do not store it
EDGES = [2.5, 10, 25, 50, 100]
SIGMA, ZQ = 17, 3.0
HALF = int(1.5 * SIGMA)
KERNEL = np.exp(-0.5 * (np.arange(-HALF, HALF + 1) / SIGMA) ** 2)
KERNEL /= KERNEL.sum()


def load(path):
    a = np.asarray(Image.open(path))
    if a.ndim != 2 or a.dtype != np.uint8 or a.shape[0] < 1 or a.shape[1] <= META + 2 * HALF:
        sys.exit(f"{path}: not an Oxford polar PNG (8-bit grey, rows x ({META} + bins), got "
                 f"{a.shape} {a.dtype})")
    return a[:, META:].astype(np.float64)


def row_stats(row):
    """Row mean and Cen2018 noise: sqrt(2 mean (x - mean)^2) over the samples below the mean."""
    m = row.mean()
    below = row[row < m]
    s = np.sqrt(2 * ((below - m) ** 2).mean()) if len(below) else 0.034 * 255
    return m, (s if s > 0 else 0.034 * 255)


def keypoint_bins(row):
    m, s = row_stats(row)
    p = np.convolve(np.pad(row, HALF, mode="reflect"), KERNEL, mode="valid") - m
    q = row - m
    k = 0.5 / (s * s)
    e = np.exp(-((q - p) ** 2) * k)
    y = q * (1 - e) + p * (e - np.exp(-p * p * k))
    idx = np.flatnonzero(y > ZQ * s)
    if len(idx) == 0:
        return []
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    return [r[np.argmax(y[r])] for r in runs]


def report(folder):
    paths = sorted(glob.glob(os.path.join(folder, "*.png")) or
                   glob.glob(os.path.join(folder, "radar", "*.png")))
    if not paths:
        sys.exit(f"{folder}: no PNG scans")
    scans = [load(p) for p in paths]
    rng = np.arange(scans[0].shape[1]) * RES
    counts = np.zeros(4)
    stats, groups = [], {}
    for x in scans:
        if x.shape[1] != scans[0].shape[1]:
            sys.exit(f"{folder}: scans of different widths")
        for row in x:
            bins = keypoint_bins(row)
            for b in bins:
                for k in range(4):
                    counts[k] += EDGES[k] <= rng[b] < EDGES[k + 1]
            stats.append(row_stats(row))
            strong = (row >= 60) & (rng > 2.5)
            first = rng[np.argmax(strong)] if strong.any() else np.inf
            g = next((f"{a:g}-{b:g} m" for a, b in [(2.5, 10), (10, 25), (25, 50)]
                      if a <= first < b), "beyond 50 m" if np.isfinite(first) else "none")
            far = row[rng > 50].mean() if (rng > 50).any() else np.nan
            groups.setdefault(g, []).append((far, len(bins)))
    st = np.array(stats)
    print(f"== {folder}: {len(scans)} scans, {scans[0].shape[1]} bins")
    print("Cen2018 keypoints per scan, 2.5-10 / 10-25 / 25-50 / 50-100 m:",
          " / ".join(f"{c / len(scans):.0f}" for c in counts))
    print("row mean p25/p50: %.1f / %.1f; threshold (mean + 3 sigma) p25/p50: %.0f / %.0f" %
          (*np.percentile(st[:, 0], [25, 50]), *np.percentile(st[:, 0] + ZQ * st[:, 1], [25, 50])))
    x = np.concatenate(scans)
    for a, b in [(10, 25), (25, 50), (50, 100), (100, 1e9)]:
        v = x[:, (rng >= a) & (rng < b)].astype(int).ravel()
        if not len(v):
            continue
        h = np.bincount(v, minlength=256) / len(v)
        top = ", ".join(f"{c}: {100 * h[c]:.0f} %" for c in np.flatnonzero(h > 0.03)[:6])
        band = f"{a:g}-{b:g} m" if b < 1e9 else f"beyond {a:g} m"
        print(f"  {band}: median {np.median(v):.0f}, q90 {np.percentile(v, 90):.0f}; "
              f"codes {top}")
    n = sum(len(g) for g in groups.values())
    for g in sorted(groups):
        a = np.array(groups[g])
        print(f"  first hit {g}: {100 * len(a) / n:.0f} % of rows, mean beyond 50 m "
              f"{np.nanmean(a[:, 0]):.1f}, keypoints per row {a[:, 1].mean():.1f}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for f in sys.argv[1:]:
        report(f)
