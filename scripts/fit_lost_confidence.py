#!/usr/bin/env python3
"""Fit the confidence table of lost frames (src/live/lost_confidence.cc) offline.

Reads the per-frame CSVs of `duet eval --no-lost-confidence --frames-csv` (columns error_ms,
confidence, lost; tracker hmm), keeps the frames flagged lost, fits a monotone (isotonic) map from
the session's confidence (after the young-offset table, before this one: hence
--no-lost-confidence) to the share of those frames within 100 ms, and prints the C++ table to
paste.

Whole-body and three-point input have tables of their own:
  scripts/fit_lost_confidence.py --full full_*.csv --head-hands points_*.csv
Fit on performances other than the ones reported on (other seeds), every rig (`--rigs all`).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fit_confidence_calibration import hmm_frames, main_per_input, monotone_map  # noqa: E402
from fit_young_offset_confidence import KNOTS  # noqa: E402

MIN_FRAMES = 1000


def table(name, paths):
    points = [(float(row["confidence"]), correct) for row, correct in hmm_frames(paths)
              if row["lost"] == "1"]
    if len(points) < MIN_FRAMES:
        sys.exit(f"{name}: {len(points)} lost frames, fewer than {MIN_FRAMES}: add performances")
    values = monotone_map(points, KNOTS)
    right = sum(c for _, c in points) / len(points)
    claimed = sum(x for x, _ in points) / len(points)
    print(f"    // {name}: fitted on " + ", ".join(p.rsplit("/", 1)[-1] for p in paths))
    print(f"    // {len(points)} lost frames, {claimed:.3f} claimed, {right:.3f} right")
    print(f"    {{{', '.join(f'{v:.4f}f' for v in values)}}},")


if __name__ == "__main__":
    main_per_input(__doc__, table)
