// BVH (Biovision hierarchy) reading and writing.
//
// Reader: any channel order per joint, 3- or 6-channel joints, End Sites, CRLF or LF, tabs or
// spaces. A joint with position channels takes them as its local translation (its OFFSET is kept
// as the rest offset). Errors name the file and line: "walk.bvh:12: expected '{' after JOINT".
// Writer: writes to "<path>.tmp" and renames, so a failure never leaves a half-written file.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/math/rotation.h"
#include "duet/motion/clip.h"
#include "duet/motion/limits.h"

namespace duet {

struct BvhReadOptions {
  // Overrides the header's Frame Time (the CMU salsa headers say 120 fps; the takes are 60 Hz).
  std::optional<double> frame_rate;
  // Metres per file unit; every length is multiplied by it. 1 keeps file units.
  double scale = 1.0;
  // Upper bound on frames a header may claim, so a bad header cannot make us allocate without
  // bound. The actual number of motion lines is checked against the header either way.
  long long max_frames = kMaxClipFrames;
};

Result<Clip> read_bvh(const std::string& path, const BvhReadOptions& options = {});
// Parses BVH text; `source_name` is used in error messages in place of a file name.
Result<Clip> parse_bvh(std::string_view text, const std::string& source_name,
                       const BvhReadOptions& options = {});

struct BvhWriteOptions {
  // File units per metre; the default writes metres.
  double units_per_metre = 1.0;
  int decimals = 6;

  // Written in the units of a file read with that scale (LoadedMotion::metres_per_unit).
  static BvhWriteOptions in_file_units(double metres_per_unit) {
    BvhWriteOptions options;
    options.units_per_metre = 1.0 / metres_per_unit;
    return options;
  }
};

std::string format_bvh(const Clip& clip, const BvhWriteOptions& options = {});

// One frame's MOTION line as format_bvh writes it: channel values in hierarchy order (depth
// first, children in index order), angles in each joint's write order. For writers that stream
// frames (live/recorder.h) so that their files read back exactly like format_bvh's. Set-up
// allocates; append() does not beyond the growth of `out`.
class BvhFrameFormatter {
 public:
  BvhFrameFormatter() = default;
  explicit BvhFrameFormatter(const Skeleton& skeleton, const BvhWriteOptions& options = {});
  // Appends the values of one pose (local translations in metres, local rotations; one per
  // joint of the skeleton), separated by spaces, without the newline.
  void append(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
              std::string& out) const;

 private:
  const Skeleton* skeleton_ = nullptr;
  std::vector<int> order_;         // joints in the order the hierarchy lists them
  std::vector<EulerOrder> euler_;  // per joint, the Euler order its angles are written in
  double units_per_metre_ = 1.0;
  int decimals_ = 6;
};
Status write_bvh(const Clip& clip, const std::string& path, const BvhWriteOptions& options = {});

}  // namespace duet
