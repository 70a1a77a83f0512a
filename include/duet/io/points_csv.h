// The three-point recording format (issue 12, docs/file-formats.md "Three-point CSV"): what a VR
// headset and two controllers report, one line per sample:
//
//   time_s,head_x,head_y,head_z,head_qx,head_qy,head_qz,head_qw,left_x,...,left_qw,right_x,...,right_qw
//
// metres, Y up, right-handed; orientations as unit quaternions whose identity faces -Z with +Y up
// (duet/motion/head_hands.h). Times in seconds, strictly increasing; samples need not be evenly
// spaced (a sensor drops frames), so the reader resamples them onto an even grid.
#pragma once

#include <optional>
#include <string>

#include "duet/base/result.h"
#include "duet/motion/clip.h"

namespace duet {

// Whether `path` names a three-point CSV: it ends in .csv, in any case (what load_motion reads as
// one).
bool is_points_csv_path(const std::string& path);

// The header line, exactly (22 columns).
const std::string& points_csv_header();

struct PointsCsvReadOptions {
  // The rate of the even grid; unset: the median sample rate, rounded to a whole Hz.
  std::optional<double> frame_rate;
  // The most frames (and samples) accepted: a gap of hours at 1 kHz would otherwise allocate
  // gigabytes.
  long long max_frames = 10'000'000;  // kMaxClipFrames
};

// A clip on make_head_hands_skeleton(), time 0 at the first sample. Gaps between samples are
// filled by linear interpolation of positions and spherical interpolation of orientations.
// Errors name the file, the line and the column.
Result<Clip> read_points_csv(const std::string& path, const PointsCsvReadOptions& options = {});
// The same from text already in memory (`name` stands for the file in messages).
Result<Clip> parse_points_csv(std::string_view text, const std::string& name,
                              const PointsCsvReadOptions& options = {});

// A head-and-hands clip as CSV text, one line per frame (times frame / rate).
std::string format_points_csv(const Clip& points);

}  // namespace duet
