// Acclaim ASF (skeleton) and AMC (motion) reading, as used by the CMU motion capture database.
//
// Handles `:units` (length scale, deg or rad), each bone's `axis` and `dof` orders, CRLF, root
// angles outside +/-180 degrees and bones without DOF. The result is a Clip whose joints are
// the ASF bones, placed at the start of each bone like CMU's BVH conversions (a bone's joint
// rotates the bone), with End Sites at the tips of leaf bones. Errors: "file:line: reason".
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/limits.h"

namespace duet {

struct AsfAmcReadOptions {
  // AMC files carry no rate; CMU captured at 120 Hz, the salsa takes (subjects 60, 61) at 60 Hz.
  double frame_rate = 120.0;
  // Metres per ASF length unit *after* the file's `:units length` is undone. CMU files are in
  // inches times `length` (0.45): metres = value / length * 0.0254. Give a value to override.
  std::optional<double> metres_per_unit;
  long long max_frames = kMaxClipFrames;
};

Result<Clip> read_asf_amc(const std::string& asf_path, const std::string& amc_path,
                          const AsfAmcReadOptions& options = {});
Result<Clip> parse_asf_amc(std::string_view asf_text, const std::string& asf_name,
                           std::string_view amc_text, const std::string& amc_name,
                           const AsfAmcReadOptions& options = {});

}  // namespace duet
