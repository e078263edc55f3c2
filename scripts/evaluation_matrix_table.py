#!/usr/bin/env python3
"""The evaluation matrix's tables (scripts/evaluation_matrix.sh) from its results.tsv files.

Each results line: column, row, held out (yes / no / layout: a column on another street layout,
printed in a table of its own), the eval JSON, the noise seed ("-" for real
columns; lines of older runs without it count as seed 1). A simulated cell is the mean over its
seeds of KITTI drift % / deg/m, followed by the range of the drift over the seeds; the column's
best and the "worst ratio" of a row are judged on those means, and only over seeds every row
of the column has (a row measured on fewer seeds is compared on its own seeds, marked with *).

With --default ROW, each table is followed by the default row's losses (columns where it is not
within 5 % of the best), each with what resolves it: on a simulated column the ratio seed by
seed (the same recordings: paired), on a real one a 90 % bootstrap interval of the ratio over
the pairs (resampled together for both rows, fixed seed), and the loss in the sensor's units
(m per km, or deg against the 0.9 deg azimuth step), so a ratio the data cannot resolve or a
loss far below the resolution reads as such.
"""
import json
import math
import random
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
            PATHS[c, r, seed] = path
    return rows, cols, held, runs


PATHS = {}  # (column, row, seed) -> eval JSON, for the per-pair figures of real columns
AZIMUTH_STEP_DEG = 0.9  # 400 azimuths a turn
BOOT = 4000


def pair_figures(column, row):
    """Per-pair errors of a real column (yaw deg; RADIATE: chain-minus-direct yaw), or None."""
    path = PATHS.get((column, row, "-"))
    if not path:
        return None
    j = json.load(open(path))[0]
    if "consistency" in j:
        return j["consistency"].get("yaw_diffs_deg")
    return [math.degrees(f["r_err_rad"]) for f in j.get("frames", [])] or None


def statistic(column, v):
    if column.startswith("radiate_real"):
        return math.sqrt(sum(x * x for x in v) / len(v))  # the column's rms
    return sum(v) / len(v)


def bootstrap_ratio(column, a, b):
    """90 % interval of statistic(a) / statistic(b), pairs resampled together."""
    rng = random.Random(1)
    n, out = len(a), []
    for _ in range(BOOT):
        idx = [rng.randrange(n) for _ in range(n)]
        den = statistic(column, [b[i] for i in idx])
        if den > 0:
            out.append(statistic(column, [a[i] for i in idx]) / den)
    out.sort()
    return out[int(0.05 * len(out))], out[int(0.95 * len(out)) - 1]


def losses(sel, rows, cell, runs, default):
    """The default row's columns beyond 5 % of the best, with what resolves each."""
    lines = []
    for c in sel:
        d = cell.get((c, default))
        v = [(cell[c, r][0], r) for r in rows if cell.get((c, r))]
        if not d or not v:
            continue
        best, br = min(v)
        if d[0] <= 1.05 * best:
            continue
        ratio = d[0] / best
        if c.startswith(REAL):
            a, b = pair_figures(c, default), pair_figures(c, br)
            if a and b and len(a) == len(b) and len(a) > 1:
                lo, hi = bootstrap_ratio(c, a, b)
                res = f"90 % interval over {len(a)} pairs {lo:.2f}-{hi:.2f}"
                res += " (not resolved)" if lo <= 1.0 else ""
            else:
                res = f"{len(a) if a else 0} pair(s): no interval"
            size = (f"{d[0] - best:.3f} deg, {(d[0] - best) / AZIMUTH_STEP_DEG * 100:.1f} % "
                    "of an azimuth step")
        else:
            sd, sb = runs[c, default], runs[c, br]
            common = sorted(s for s in sd if s in sb and sd[s] and sb[s])
            per = [sd[s][0] / sb[s][0] for s in common]
            res = "per seed " + " / ".join(f"{x:.2f}" for x in per)
            res += " (worse on every seed)" if per and min(per) > 1.0 else " (not on every seed)"
            size = f"{(d[0] - best) * 10:.2f} m per km"
        lines.append(f"- {c}: {ratio:.2f} against {br}; {res}; {size}")
    if lines:
        print(f"\n{default}: columns beyond 5 % of the best\n")
        print("\n".join(lines))


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


def table(sel, title, rows, cell, runs, default=None):
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
    if default in rows:
        losses(sel, rows, cell, runs, default)


def main():
    args, default = sys.argv[1:], None
    if args[:1] == ["--default"]:
        if len(args) < 2:
            sys.exit("error: --default needs a row label")
        default, args = args[1], args[2:]
    if not args:
        sys.exit("usage: evaluation_matrix_table.py [--default ROW] RESULTS.tsv [MORE.tsv ...]")
    rows, cols, held, runs = load(args)
    if default is not None and default not in rows:
        print(f"note: --default {default}: not among the rows ({', '.join(rows)}); its losses "
              "are not listed", file=sys.stderr)
    cell = aggregate(runs)
    table([c for c in cols if held[c] not in ("yes", "layout")],
          "Columns used while tuning (simulated: KITTI drift % / deg/m, mean over the noise seeds, "
          "(range of the drift over the seeds); oxford_real: mean yaw error deg / translation error % "
          "per pair; radiate_real_consistency: chain-vs-direct rms yaw deg / step length m over pairs "
          "two scans apart, no ground truth; bold: within 5 % of the column's best)", rows, cell, runs,
          default)
    table([c for c in cols if held[c] == "layout"],
          "Street layouts 1 and 2 of some sensor columns (--variant; KITTI drift % / deg/m, mean over "
          "the noise seeds)", rows, cell, runs, default)
    table([c for c in cols if held[c] == "yes"], "Held-out columns (not looked at while tuning)",
          rows, cell, runs, default)


if __name__ == "__main__":
    main()
