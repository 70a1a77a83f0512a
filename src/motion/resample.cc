#include "duet/motion/resample.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "duet/motion/limits.h"

namespace duet {

double resampled_frame_count(const Clip& clip, double frame_rate) {
  if (clip.frame_count() == 0) return 0.0;
  const double last_time = (clip.frame_count() - 1) / clip.frame_rate();
  return std::floor(last_time * frame_rate + 1e-9) + 1.0;
}

Clip resample(const Clip& clip, double frame_rate) {
  assert(frame_rate > 0.0 && clip.frame_rate() > 0.0);
  const double count = resampled_frame_count(clip, frame_rate);
  assert(count <= static_cast<double>(kMaxClipFrames));
  const auto frames = static_cast<int>(count);
  Clip out(clip.skeleton_ptr(), frame_rate, frames);
  Pose pose;
  for (int f = 0; f < frames; ++f) {
    clip.sample(f / frame_rate, pose);
    std::ranges::copy(pose.translations_ls, out.translations_ls(f).begin());
    std::ranges::copy(pose.rotations_ls, out.rotations_ls(f).begin());
  }
  return out;
}

}  // namespace duet
