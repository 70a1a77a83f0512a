// Lost on non-dance input (issue 11): motion that no part of the library explains (a walk, a
// wave, another style of dance, on any rig) must be reported lost, not followed. `duet eval
// --non-dance` runs such clips through the follower and reports the share of lost frames.
#pragma once

#include <memory>
#include <string>

#include "duet/base/result.h"
#include "duet/follow/tracker.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"

namespace duet {

struct NonDanceResult {
  std::string name;  // the clip's name (its file's stem)
  long long frames = 0;
  long long lost = 0;  // frames the follower reported lost

  double lost_fraction() const {
    return frames > 0 ? static_cast<double>(lost) / static_cast<double>(frames) : 0.0;
  }
};

// The clip played over and over until it lasts at least min_duration_s: a user who waves or walks
// for half a minute, not the 2-3 s a short clip holds. Each repeat's root is moved on
// horizontally by the clip's own first-to-last displacement, so a walk walks on; each seam is one
// step back to the first pose. A clip already that long (or empty) is returned as it is.
Clip looped_clip(const Clip& clip, double min_duration_s);

// Every frame of `input` (any rig whose body roles are known) through a follow session of
// `library` with `tracker`, at the clip's own timing; for a three-point library, the clip's head
// and hands (head_hands_clip), as a headset would give them. An error when the session cannot be
// made (the rig lacks roles the features need).
Result<NonDanceResult> follow_non_dance(const DuetLibrary& library, const LoadedMotion& input,
                                        std::string name, std::unique_ptr<Tracker> tracker);

}  // namespace duet
