#include "duet/motion/resample.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace duet {

Clip resample(const Clip& clip, double frame_rate) {
  assert(frame_rate > 0.0 && clip.frame_rate() > 0.0);
  const double last_time = clip.frame_count() > 0 ? (clip.frame_count() - 1) / clip.frame_rate() : 0;
  const int frames =
      clip.frame_count() == 0 ? 0 : static_cast<int>(std::floor(last_time * frame_rate + 1e-9)) + 1;
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
