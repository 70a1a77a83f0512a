#!/usr/bin/env python3
"""Fit the young-offset confidence table (src/live/young_offset_confidence.cc) offline.

Reads the per-frame CSVs of `duet eval --frames-csv` (columns error_ms, tracker_confidence,
rig_offset, rig_offset_learnt_s; tracker hmm), groups the frames by the band of the rig's posture
offset and the band of the seconds it has been learnt, fits in each cell a monotone (isotonic) map
from the tracker's confidence to the share of frames within 100 ms, and prints the C++ table to
paste. A cell with fewer than MIN_FRAMES frames keeps the tracker's confidence (the identity).

Whole-body and three-point input have tables of their own:
  scripts/fit_young_offset_confidence.py --full full_*.csv --head-hands points_*.csv
Fit on performances other than the ones reported on (other seeds), every rig (`--rigs all`).
"""
import bisect
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fit_confidence_calibration import hmm_frames, main_per_input, monotone_map  # noqa: E402

# Must match src/live/young_offset_confidence.cc (KNOTS: duet/math/lookup_table.h's
# kConfidenceKnots, which scripts/fit_lost_confidence.py shares).
OFFSET_EDGES = [0.03, 0.06, 0.1]  # RMS per posture dimension, standardised units
LEARNT_EDGES = [1.0, 2.0, 3.0, 5.0]  # seconds; from SETTLED_S on the identity
SETTLED_S = 8.0
KNOTS = [k / 10.0 for k in range(10)] + [0.95, 0.99, 1.0]
MIN_FRAMES = 300


def read(paths):
    cells = {}
    for row, correct in hmm_frames(paths):
        learnt = float(row["rig_offset_learnt_s"])
        if learnt >= SETTLED_S:
            continue
        cell = (bisect.bisect_right(OFFSET_EDGES, float(row["rig_offset"])),
                bisect.bisect_right(LEARNT_EDGES, learnt))
        cells.setdefault(cell, []).append((float(row["tracker_confidence"]), correct))
    return cells


def table(name, paths):
    cells = read(paths)
    print(f"    // {name}: fitted on " + ", ".join(p.rsplit("/", 1)[-1] for p in paths))
    print("    {")
    for o in range(len(OFFSET_EDGES) + 1):
        print("        {")
        for t in range(len(LEARNT_EDGES) + 1):
            points = cells.get((o, t), [])
            if len(points) < MIN_FRAMES:
                values = list(KNOTS)
                note = f"{len(points)} frames: as the tracker says"
            else:
                values = monotone_map(points, KNOTS)
                right = sum(c for _, c in points) / len(points)
                claimed = sum(x for x, _ in points) / len(points)
                note = f"{len(points)} frames, {claimed:.3f} claimed, {right:.3f} right"
            print(f"            // offset band {o}, learnt band {t}: {note}")
            print(f"            {{{', '.join(f'{v:.4f}f' for v in values)}}},")
        print("        },")
    print("    },")


if __name__ == "__main__":
    main_per_input(__doc__, table)
