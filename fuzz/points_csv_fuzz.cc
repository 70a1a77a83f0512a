// libFuzzer target for the three-point CSV reader (duet/io/points_csv.h). Seeds:
// fuzz/corpus/points_csv/.
//
// Properties checked, beyond "no crash, no hang, no unbounded allocation":
// - an error names the file ("f.csv...") and is one line;
// - a clip is on the head-and-hands skeleton, its rate within 1-1000 Hz, at least 2 frames and at
//   most max_frames, every position finite and every orientation a finite unit quaternion;
// - what the writer makes of the clip reads back with the same frame count and rate.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "duet/io/points_csv.h"
#include "duet/motion/head_hands.h"

namespace {

void check(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "points_csv_fuzz: property violated: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  duet::PointsCsvReadOptions options;
  options.max_frames = 100'000;
  const duet::Result<duet::Clip> result = duet::parse_points_csv(text, "f.csv", options);
  if (!result) {
    const std::string& message = result.error().message;
    check(message.rfind("f.csv", 0) == 0, "error names the file");
    check(message.find('\n') == std::string::npos, "error is one line");
    return 0;
  }
  const duet::Clip& clip = result.value();
  check(clip.joint_count() == duet::kHeadHandsJointCount, "head-and-hands skeleton");
  check(clip.frame_rate() >= 1.0 && clip.frame_rate() <= 1000.0, "rate in range");
  check(clip.frame_count() >= 2 && clip.frame_count() <= options.max_frames, "frame count");
  for (int f = 0; f < clip.frame_count(); ++f) {
    for (const duet::Quat& q : clip.rotations_ls(f)) {
      check(q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-6, "unit finite rotation");
    }
    for (const duet::Vec3& t : clip.translations_ls(f)) check(t.allFinite(), "finite position");
  }
  if (clip.frame_count() <= 1000) {
    duet::PointsCsvReadOptions again_options = options;
    again_options.frame_rate = clip.frame_rate();
    const duet::Result<duet::Clip> again =
        duet::parse_points_csv(duet::format_points_csv(clip), "g.csv", again_options);
    check(again.ok(), "the written clip reads back");
    check(again.value().frame_count() == clip.frame_count(), "same frame count read back");
  }
  return 0;
}
