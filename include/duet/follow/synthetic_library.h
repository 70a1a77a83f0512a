// A large template library made from a real one, for scale tests and benchmarks (issue 13): the
// real takes replicated with time warps and noise until the library has the asked number of
// states. Each copy plays one real take at a random speed (linear interpolation between its
// frames; the velocity dimensions scale with the speed, as a faster dancer's would) with Gaussian
// noise on every feature, so no two copies are alike and the follower's beam meets as many
// look-alike places as in a big real library. Given the features' mirror map
// (duet/features/feature_mirror.h), every second copy is the mirror image of its take: the dance
// with left and right swapped, a new dance for the follower.
//
// Each copy remembers where it comes from (SyntheticTakeSource), so that a grown duet library
// (DuetLibrary with LibraryOptions::grow_to_states) can show the partner of the real take at the
// real frame whichever copy the follower is in.
#pragma once

#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_mirror.h"
#include "duet/follow/template_model.h"

namespace duet {

struct SyntheticLibraryOptions {
  int num_states = 100000;
  float min_speed = 0.8f;  // each copy plays at a speed in [min_speed, max_speed]
  float max_speed = 1.25f;
  float noise = 0.02f;  // standard deviation of the noise added to every feature
  unsigned seed = 1;
  // Keep the real takes, unchanged, as the library's first takes; the copies follow them.
  bool keep_real_takes = false;
  // Non-empty (one entry per dimension, feature_mirror()): every second copy is mirrored.
  std::vector<MirroredDim> mirror;
};

// Where a take of a synthetic library comes from.
struct SyntheticTakeSource {
  int real_take = 0;
  float speed = 1.0f;  // real frames per copy frame
  int real_length = 0;  // frames of the real take
  bool mirrored = false;  // left and right swapped
  // The real take's frame nearest to the copy's frame `frame` (>= 0).
  int real_frame(int frame) const noexcept;
};

// Copies of real's takes, in turn, until num_states states (the last copy cut short, but kept at
// least 3 frames long). Same dimensions, velocity dimensions and frame rate as real. Allocates.
Result<TemplateModel> synthesize_library(const TemplateModel& real,
                                         const SyntheticLibraryOptions& options);

// The source of each take of synthesize_library(real, options), in order, without building the
// features (cheap: a reader of a cached grown library calls it).
Result<std::vector<SyntheticTakeSource>> synthetic_take_sources(
    const TemplateModel& real, const SyntheticLibraryOptions& options);

}  // namespace duet
