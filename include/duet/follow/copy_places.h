// Where each state of a grown library sits in the captured takes, so that the follower's
// confidence counts the posterior mass on every copy of a moment (issue 13).
//
// A library grown with time-warped copies of its takes (synthetic_library.h,
// LibraryOptions::grow_to_states) holds each captured moment many times: at 1M states about 36
// copies of every frame of the 14 salsa duets. The posterior near the estimate is then shared
// between the copies, and the confidence (the mass within the window of the estimate, in its own
// take) fell with it although every copy is the same place: ECE 24 % on `harsh` and 7.5 % on
// `improv-30hz-noisy` at 1M states, against <= 3.3 % on the captured library. With this map the
// window is taken in the captured takes' frames, over every state whose place falls in it.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/synthetic_library.h"

namespace duet {

class TemplateModel;

class CopyPlaces {
 public:
  // `model` holds the captured takes first (its first captured_takes takes, as captured), then
  // one take per source: sources[k] is what take captured_takes + k copies. Allocates (O(M)).
  static Result<CopyPlaces> build(const TemplateModel& model, int captured_takes,
                                  std::span<const SyntheticTakeSource> sources);

  // The state of the captured takes that `state` shows (itself for a captured state).
  int place_of(int state) const { return place_[static_cast<std::size_t>(state)]; }
  int num_states() const { return static_cast<int>(place_.size()); }

  // The posterior mass (posterior has num_states() entries) on every state whose place is within
  // `window` frames of state's place, in the same captured take. Reads about (2 window + 1) x
  // copies entries. Allocates nothing.
  float window_mass(const float* posterior, int state, int window) const noexcept;
  // The same when only the states in `support` can hold mass (a beam): O(support).
  float window_mass(const float* posterior, int state, int window,
                    std::span<const int> support) const noexcept;

 private:
  // The captured states [first, second) within `window` frames of state's place, in its take.
  std::pair<int, int> window_of(int state, int window) const noexcept;

  std::vector<int> place_;         // per state: the captured state it shows
  std::vector<int> take_start_;    // the captured takes' first states, and their end
  std::vector<int> copy_offsets_;  // per captured state c: copies_[offsets[c], offsets[c + 1])
  std::vector<int> copies_;        // the states showing each captured state, grouped by it
};

}  // namespace duet
