#!/usr/bin/env python3
"""Before/after realism table of the calibrated sensors (README "Calibrated sensors",
docs/diagnose.md) from the appearance reports scripts/calibrate_sensors.sh writes.

Usage: scripts/appearance_table.py OUT [SAMPLE ...]   (OUT/<sample>/appearance/appearance.json;
SAMPLE: oxford, mulran, boreas_rt, radiate, default all four: one sample's column alone, e.g. a
refit run on its own)
Prints a markdown table (real fit part / real held out / sim before / sim after per sample) and,
per sample and part, the fitted figures still over 15 % after the fit.
"""
import json
import os
import sys

SAMPLES = [("oxford", "Oxford CTS350-X"), ("mulran", "MulRan CIR204-H"),
           ("boreas_rt", "Boreas-RT RAS6"), ("radiate", "RADIATE*")]
BANDS = ["2.5-10 m", "10-25 m", "25-50 m", "50-100 m"]
FIGS = ["mean", "q90", "cacfar", "cen2018"]


def load(out, name):
    path = os.path.join(out, name, "appearance", "appearance.json")
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"{path}: cannot read the appearance report ({e})")


def scene_dependent(j):
    return {(d["band"], d["figure"]) for d in j.get("scene_dependent_not_fitted", [])}


def gaps(j, part, col):
    """Relative gaps |sim - real| / real of the fitted figures, by name."""
    rb, skip, g = j["realism_bands"], scene_dependent(j), {}
    for k, band in enumerate(BANDS):
        for f in FIGS:
            if (k, f) in skip:
                continue
            r, s = rb[part][f][k], rb[col][f][k]
            if r < 0 or s < 0:
                continue
            g[f"{band} {f}"] = abs(s - r) / r if r > 0 else (1.0 if s > 0 else 0.0)
    return g


def worst(g, far_only=False):
    v = [x for n, x in g.items() if not far_only or not n.startswith("2.5-10")]
    return 100 * max(v) if v else float("nan")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    known = [name for name, _ in SAMPLES]
    for name in sys.argv[2:]:
        if name not in known:
            sys.exit(f"{name}: not a sample ({', '.join(known)})")
    samples = [(n, l) for n, l in SAMPLES if len(sys.argv) == 2 or n in sys.argv[2:]]
    reps = [(label, load(sys.argv[1], name)) for name, label in samples]
    parts = [("recording_fit", "fit part"), ("recording_holdout", "held-out part")]
    print("| figure: real fit part / real held out / sim before / sim after | " +
          " | ".join(label for label, _ in reps) + " |")
    print("|---" * (len(reps) + 1) + "|")

    def quad(j, f, bands):
        rb = j["realism_bands"]
        cols = ["recording_fit", "recording_holdout", "sim_before", "sim_after"]
        return " / ".join(f"{sum(rb[c][f][k] for k in bands):.0f}" if c in rb else "-"
                          for c in cols)

    print("| Cen2018 keypoints/scan, 10-100 m | " +
          " | ".join(quad(j, "cen2018", [1, 2, 3]) for _, j in reps) + " |")
    print("| Cen2018 keypoints/scan, 2.5-10 m (scene-dependent, not fitted) | " +
          " | ".join(quad(j, "cen2018", [0]) for _, j in reps) + " |")
    print("| plain CA-CFAR cells/scan, 2.5-100 m | " +
          " | ".join(quad(j, "cacfar", [0, 1, 2, 3]) for _, j in reps) + " |")
    def worst_gap_rows(label, far_only):
        for part, what in parts:
            cells = []
            for _, j in reps:
                if part not in j["realism_bands"]:
                    cells.append("-")
                    continue
                seeds = j.get("worst_band_gap_over_seeds", {})
                key = "" if part == "recording_fit" else "holdout_"
                if j.get("render_seeds", 1) > 1 and key + "after" in seeds:
                    # --render-seeds N: the mean of each seed's worst gap [its range]
                    b, a = seeds[key + "before"], seeds[key + "after"]
                    cells.append(f"{100 * b['mean']:.0f} % [{100 * b['min']:.0f}-{100 * b['max']:.0f}] -> "
                                 f"{100 * a['mean']:.0f} % [{100 * a['min']:.0f}-{100 * a['max']:.0f}]")
                    continue
                b, a = gaps(j, part, "sim_before"), gaps(j, part, "sim_after")
                cells.append(f"{worst(b, far_only):.0f} % -> {worst(a, far_only):.0f} %")
            print(f"| {label}, {what} | " + " | ".join(cells) + " |")
    worst_gap_rows("worst per-band gap, fitted figures (15 of 16)", False)
    worst_gap_rows("the same at 10-100 m (12 figures)", True)
    print()
    # The recording's own split-half difference |held out - fit part| / fit part per figure,
    # next to each gap: a held-out gap of that size is the sample's own scatter (still not met).
    for (name, label), (_, j) in zip(samples, reps):
        halves = (gaps(j, "recording_fit", "recording_holdout")
                  if "recording_holdout" in j["realism_bands"] else {})
        for part, what in parts:
            if part not in j["realism_bands"]:
                continue
            over = sorted(((n, x) for n, x in gaps(j, part, "sim_after").items() if x > 0.15),
                          key=lambda t: -t[1])
            text = ", ".join(f"{n} {100 * x:.0f} %" +
                             (f" (halves differ {100 * halves[n]:.0f} %)" if n in halves else "")
                             for n, x in over) or "none"
            print(f"- {label}, {what}: over 15 % (real halves' own difference): {text}")
        # Held-out check with each part's own scene (appearance_holdout.cpp): the verdicts.
        verdicts = {f["figure"]: f for f in j.get("held_out_figures", [])}
        for n, x in sorted(gaps(j, "recording_holdout", "sim_after").items() if verdicts else [],
                           key=lambda t: -t[1]):
            if x > 0.15 and n in verdicts:
                f = verdicts[n]
                print(f"  - {label}, held out {n}: carry-over {100 * f['carry']:.1f} %, "
                      f"net of the scene {100 * f['gap_net']:.1f} %: {f['verdict']}")
    if any("recording_holdout" in j["realism_bands"] for _, j in reps):
        print()
        print("| real data's own split-half difference, 10-100 m (largest, figure) | " +
              " | ".join(label for label, _ in reps) + " |")
        print("|---" * (len(reps) + 1) + "|")
        cells = []
        for _, j in reps:
            if "recording_holdout" not in j["realism_bands"]:
                cells.append("-")
                continue
            h = {n: x for n, x in gaps(j, "recording_fit", "recording_holdout").items()
                 if not n.startswith("2.5-10")}
            n = max(h, key=h.get)
            cells.append(f"{100 * h[n]:.0f} % ({n})")
        print("| largest | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
