// BVH (Biovision hierarchy) reading and writing.
//
// Reader: any channel order per joint, 3- or 6-channel joints, End Sites, CRLF or LF, tabs or
// spaces. A joint with position channels takes them as its local translation (its OFFSET is kept
// as the rest offset). Errors name the file and line: "walk.bvh:12: expected '{' after JOINT".
// Writer: writes to "<path>.tmp" and renames, so a failure never leaves a half-written file.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "duet/base/result.h"
#include "duet/motion/clip.h"

namespace duet {

struct BvhReadOptions {
  // Overrides the header's Frame Time (the CMU salsa headers say 120 fps; the takes are 60 Hz).
  std::optional<double> frame_rate;
  // Metres per file unit; every length is multiplied by it. 1 keeps file units.
  double scale = 1.0;
  // Upper bound on frames a header may claim, so a bad header cannot make us allocate without
  // bound. The actual number of motion lines is checked against the header either way.
  long long max_frames = 10'000'000;
};

Result<Clip> read_bvh(const std::string& path, const BvhReadOptions& options = {});
// Parses BVH text; `source_name` is used in error messages in place of a file name.
Result<Clip> parse_bvh(std::string_view text, const std::string& source_name,
                       const BvhReadOptions& options = {});

struct BvhWriteOptions {
  // File units per metre; the default writes metres.
  double units_per_metre = 1.0;
  int decimals = 6;
};

std::string format_bvh(const Clip& clip, const BvhWriteOptions& options = {});
Status write_bvh(const Clip& clip, const std::string& path, const BvhWriteOptions& options = {});

}  // namespace duet
