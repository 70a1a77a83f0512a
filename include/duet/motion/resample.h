// Changing a clip's frame rate: translations interpolated linearly, rotations by slerp.
#pragma once

#include "duet/motion/clip.h"

namespace duet {

// The number of frames resample() makes, computed without overflow (a huge or non-finite rate
// gives a huge or infinite count, never a wrapped one): check it against kMaxClipFrames first.
double resampled_frame_count(const Clip& clip, double frame_rate);

// A clip at `frame_rate` covering the same duration: frame k samples time k / frame_rate,
// for every k with that time within the source's first and last frame. Needs a positive rate
// and resampled_frame_count() <= kMaxClipFrames.
Clip resample(const Clip& clip, double frame_rate);

}  // namespace duet
