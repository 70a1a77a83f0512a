// Changing a clip's frame rate: translations interpolated linearly, rotations by slerp.
#pragma once

#include "duet/motion/clip.h"

namespace duet {

// A clip at `frame_rate` covering the same duration: frame k samples time k / frame_rate,
// for every k with that time within the source's first and last frame.
Clip resample(const Clip& clip, double frame_rate);

}  // namespace duet
