#!/usr/bin/env python3
"""Fit the HMM's confidence calibration (src/follow/confidence_calibration.cc) offline.

Reads the per-frame CSVs of `duet eval --frames-csv` (columns error_ms, window_mass,
sensor_noise_per_dim; tracker hmm), groups the frames by sensor-noise band, fits in each band a
monotone (isotonic, pool-adjacent-violators) map from the posterior window mass to the share of
frames within 100 ms, and prints it sampled at fixed mass knots as the C++ table to paste.

Fit on performances other than the ones reported on (other takes and seed), e.g.
  for n in 2 4.5 6.93; do duet eval --library libraries/cmu-salsa.toml --trackers hmm \
      --no-partner-metrics --takes 2,4,9,11 --seed 7 --noise-deg $n --frames-csv train_$n.csv; done
  scripts/fit_confidence_calibration.py train_*.csv
"""
import argparse
import bisect
import csv
import math
import sys

# Must match src/follow/confidence_calibration.cc.
NOISE_EDGES = [3e-4, 1.5e-3, 4e-3, 8e-3]  # band b: NOISE_EDGES[b-1] <= noise < NOISE_EDGES[b]
# Knots of the map in the coordinate x(mass) below: 0, 0.1, ..., 1.
KNOTS = [k / 10.0 for k in range(10)] + [0.9 + k * 0.01 for k in range(11)]
TOLERANCE_MS = 100.0


def coordinate(mass):
    """x(mass): mass itself up to 0.9, then the number of nines (-log10(1 - mass), 1 to 6) spread
    over (0.9, 1]: nearly every frame's mass is above 0.99, and 0.999 and 0.999999 differ in how
    often they are right under a noisy sensor (93% and 99.7% at 4 degrees per axis)."""
    mass = min(max(mass, 0.0), 1.0)
    if mass <= 0.9:
        return mass
    nines = 6.0 if mass >= 1.0 - 1e-6 else -math.log10(1.0 - mass)
    return 0.9 + 0.1 * (min(nines, 6.0) - 1.0) / 5.0


def isotonic(points):
    """points: sorted (x, y); returns blocks [(x_mean, y_mean, weight)] non-decreasing in y.
    Points with the same x are pooled first (else their order would fake a rising map)."""
    pooled = []
    for x, y in points:
        if pooled and pooled[-1][0] == x:
            w = pooled[-1][2]
            pooled[-1] = [x, (pooled[-1][1] * w + y) / (w + 1.0), w + 1.0]
        else:
            pooled.append([x, y, 1.0])
    blocks = []
    for x, y, weight in pooled:
        blocks.append([x, y, weight])
        while len(blocks) > 1 and blocks[-2][1] > blocks[-1][1]:
            x2, y2, w2 = blocks.pop()
            x1, y1, w1 = blocks[-1]
            w = w1 + w2
            blocks[-1] = [(x1 * w1 + x2 * w2) / w, (y1 * w1 + y2 * w2) / w, w]
    return blocks


def sample(blocks, knot):
    """The isotonic map at a knot: linear between block centres, flat beyond the ends."""
    xs = [b[0] for b in blocks]
    i = bisect.bisect_left(xs, knot)
    if i == 0:
        return blocks[0][1]
    if i == len(blocks):
        return blocks[-1][1]
    (x0, y0, _), (x1, y1, _) = blocks[i - 1], blocks[i]
    t = 0.0 if x1 == x0 else (knot - x0) / (x1 - x0)
    return y0 + t * (y1 - y0)


def hmm_frames(paths):
    """Every hmm frame of the frames CSVs: (row, 1.0 if within TOLERANCE_MS else 0.0)."""
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["tracker"] == "hmm":
                    yield row, 1.0 if float(row["error_ms"]) <= TOLERANCE_MS else 0.0


def monotone_map(points, knots):
    """The isotonic fit of (x, correct) points sampled at the knots, clamped to [0, 1] and
    monotone after sampling too (interpolation keeps it; the clamp guards against rounding)."""
    blocks = isotonic(sorted(points))
    values = [min(max(sample(blocks, k), 0.0), 1.0) for k in knots]
    for i in range(1, len(values)):
        values[i] = max(values[i], values[i - 1])
    return values


def main_per_input(doc, table):
    """The command line of a script that fits one table per kind of input: --full and
    --head-hands, each a list of frames CSVs, given to table(name, paths) in that order."""
    parser = argparse.ArgumentParser(description=doc,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--full", nargs="+", required=True, help="whole-body frames CSVs")
    parser.add_argument("--head-hands", nargs="+", required=True, help="three-point frames CSVs")
    args = parser.parse_args()
    table("whole body", args.full)
    table("head and hands", args.head_hands)


def main(paths):
    bands = [[] for _ in range(len(NOISE_EDGES) + 1)]
    for row, correct in hmm_frames(paths):
        band = bisect.bisect_right(NOISE_EDGES, float(row["sensor_noise_per_dim"]))
        bands[band].append((coordinate(float(row["window_mass"])), correct))
    print("// Fitted by scripts/fit_confidence_calibration.py on " +
          ", ".join(p.rsplit("/", 1)[-1] for p in paths))
    for b, points in enumerate(bands):
        if not points:
            sys.exit(f"noise band {b} has no frames: add performances at that noise level")
        values = monotone_map(points, KNOTS)
        print(f"    // band {b}: {len(points)} frames")
        print(f"    {{{', '.join(f'{v:.4f}f' for v in values)}}},")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
