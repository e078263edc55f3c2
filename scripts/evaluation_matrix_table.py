#!/usr/bin/env python3
"""The evaluation matrix's tables (scripts/evaluation_matrix.sh) from its results.tsv files.

Each results line: column, row, held out (yes / no / layout: a column on another street layout,
printed in a table of its own), the eval JSON, the noise seed ("-" for real
columns; lines of older runs without it count as seed 1). A simulated cell is the mean over its
seeds of KITTI drift % / deg/m, followed by the range of the drift over the seeds; the column's
best and the "worst ratio" of a row are judged on those means, and only over seeds every row
of the column has (a row measured on fewer seeds is compared on its own seeds, marked with *).
"""
import json
import math
import sys

REAL = ("oxford_real", "radiate_real")


def read_cell(path, column):
    """(first figure, second figure, length m, count) of one eval JSON, or None."""
    j = json.load(open(path))[0]
    if "consistency" in j:
        k = j["consistency"]
        return (k["yaw_rms_deg"], k["length_rms_m"], 0.0, k["pairs"]) if k["pairs"] else None
    if column.startswith("oxford_real"):
        fr = j["frames"]
        if not fr:
            return None
        yaw = sum(math.degrees(f["r_err_rad"]) for f in fr) / len(fr)
        t = sum(f["t_err_pct"] for f in fr) / len(fr)
        return (yaw, t, j.get("path_length_m", 0.0), len(fr))
    if not j["drift_valid"]:
        return None
    return (j["t_err_pct"], j["r_err_deg_per_m"], j["path_length_m"], j["poses"])


def load(files):
    rows, cols, held, runs = [], [], {}, {}
    for f in files:
        for n, line in enumerate(open(f), 1):
            parts = line.rstrip("\n").split("\t")
            if len(parts) not in (4, 5):
                sys.exit(f"error: {f}:{n}: expected 4 or 5 tab-separated fields, got {len(parts)}")
            c, r, h, path = parts[:4]
            seed = parts[4] if len(parts) == 5 else "1"
            if c not in cols:
                cols.append(c)
            if r not in rows:
                rows.append(r)
            held[c] = h
            runs.setdefault((c, r), {})[seed] = read_cell(path, c)
    return rows, cols, held, runs


def aggregate(runs):
    """Mean cell per (column, row): (first, second, length, count, lo, hi, seeds)."""
    cell = {}
    for key, by_seed in runs.items():
        v = [x for x in by_seed.values() if x]
        if not v or len(v) < len(by_seed):  # a failed seed makes the cell n/a: no silent mean
            cell[key] = None
            continue
        first = [x[0] for x in v]
        cell[key] = (sum(first) / len(v), sum(x[1] for x in v) / len(v), v[0][2], v[0][3],
                     min(first), max(first), len(v))
    return cell


def table(sel, title, rows, cell, runs):
    if not sel:
        return
    print(f"\n{title}\n")
    print("| estimator | " + " | ".join(sel) + " | worst ratio to the column's best |")
    print("|---|" + "---|" * (len(sel) + 1))
    seeds = {c: max((len(runs.get((c, r), {})) for r in rows), default=0) for c in sel}
    best = {}
    for c in sel:
        v = [cell[c, r][0] for r in rows if cell.get((c, r))]
        best[c] = min(v) if v else None
    for r in rows:
        out = []
        for c in sel:
            x = cell.get((c, r))
            if not x:
                out.append("n/a")
                continue
            real = c.startswith(REAL)
            s = f"{x[0]:.3f} / {x[1]:.4f}" if real else f"{x[0]:.2f} / {x[1]:.4f}"
            if best[c] is not None and x[0] <= 1.05 * best[c]:
                s = f"**{s}**"
            if x[6] > 1:
                s += f" ({x[4]:.2f}-{x[5]:.2f})"
            if x[6] < seeds[c]:
                s += f" *{x[6]} seed{'s' if x[6] > 1 else ''}"
            out.append(s)
        # The default is chosen by this: its worst ratio over the columns (first figure, means).
        ratios = [cell[c, r][0] / best[c] for c in sel if cell.get((c, r)) and best[c]]
        worst = f"{max(ratios):.2f}" if len(ratios) == len(sel) else "n/a"
        print(f"| {r} | " + " | ".join(out) + f" | {worst} |")
    lens = []
    for c in sel:
        x = next((cell[c, r] for r in rows if cell.get((c, r))), None)
        if x:
            unit = "pairs" if c.startswith(REAL) else "scans"
            n = f", {seeds[c]} seeds" if seeds[c] > 1 else ""
            lens.append(f"{c}: {x[2]:.0f} m, {x[3]} {unit}{n}")
    print("\n" + "; ".join(lens))


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: evaluation_matrix_table.py RESULTS.tsv [MORE.tsv ...]")
    rows, cols, held, runs = load(sys.argv[1:])
    cell = aggregate(runs)
    table([c for c in cols if held[c] not in ("yes", "layout")],
          "Columns used while tuning (simulated: KITTI drift % / deg/m, mean over the noise seeds, "
          "(range of the drift over the seeds); oxford_real: mean yaw error deg / translation error % "
          "per pair; radiate_real_consistency: chain-vs-direct rms yaw deg / step length m over pairs "
          "two scans apart, no ground truth; bold: within 5 % of the column's best)", rows, cell, runs)
    table([c for c in cols if held[c] == "layout"],
          "Street layouts 1 and 2 of some sensor columns (--variant; KITTI drift % / deg/m, mean over "
          "the noise seeds)", rows, cell, runs)
    table([c for c in cols if held[c] == "yes"], "Held-out columns (not looked at while tuning)",
          rows, cell, runs)


if __name__ == "__main__":
    main()
