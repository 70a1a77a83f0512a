// A library of duets (method.md 1): captured pairs, the user's role, and everything built from
// them offline for following: per-take template and response clips, template features
// standardised over the whole library, and the follower's template model.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_extractor.h"
#include "duet/features/posture_bias.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/jump_candidates.h"
#include "duet/follow/synthetic_library.h"
#include "duet/follow/template_model.h"
#include "duet/io/motion_file.h"
#include "duet/motion/arms_forward.h"

namespace duet {

// Which dancer the user dances. The user's clip is the template; the other is the response.
enum class DancerRole { kLeader, kPartner };
bool parse_dancer_role(const std::string& text, DancerRole& role);
const char* dancer_role_name(DancerRole role);

// One dancer of a captured duet, as load_motion() takes it: {take.bvh} or {skeleton.asf,
// motion.amc}. On the command line it is one word, "take.bvh" or "skeleton.asf+motion.amc"
// (duet/io/motion_argument.h); in a library file a string or a two-element array.
using MotionFiles = std::vector<std::string>;

struct PairFiles {
  MotionFiles leader;
  MotionFiles partner;
  std::string name = {};  // the take's name; empty: the stem of the leader's motion file
};

struct LibraryOptions {
  DancerRole role = DancerRole::kLeader;
  MotionLoadOptions load;  // frame-rate and unit overrides for the pair files
  FeatureSpec features;
  // Trim a pair whose two clips differ in length to the shorter one instead of failing.
  bool trim_to_shorter = false;
  // Grow the follower's library to this many template states with time-warped, noisy copies of
  // the takes (synthetic_library.h), for scale tests (issue 13); 0: the takes as captured. A copy
  // is followed like any take; its place is reported as the real take's (DuetLibrary::place_of).
  int grow_to_states = 0;
  unsigned grow_seed = 1;
  // A model cache file (model_cache.h): the template model and the beam's jump candidate index
  // are read from it when it was written for this library (its features, takes and growth),
  // else built and written to it. Empty: no cache.
  std::string model_cache;
};

// A place in the library's captured takes.
struct LibraryPlace {
  int take = -1;
  int frame = -1;
};

struct DuetTake {
  std::string name;  // PairFiles::name, else the leader's motion file stem, e.g. "60_01_scaled"
  LoadedMotion template_motion;
  LoadedMotion response_motion;
  int first_state = 0;  // index of this take's frame 0 among all template states
};

// The follower's parameters for a library of these input points (FeatureSpec::input_points).
// Three points (a headset and two controllers) hold a far place the input fits poorly
// (FollowParams::unexplained_jump_hold_s) for kHeadHandsUnexplainedJumpHoldS, not the body's 0.4
// s: they fit the template less closely than a body, so on another rig nearly every far place is
// one the input fits poorly, true jumps too; from places followed for a while
// (FollowParams::unexplained_jump_hold_after_s) the hold halves the look-alike excursions there
// (docs/evaluation.md, "Three points hold a look-alike"; 0.4 s removed 7 more of 187 at the same
// accuracy: the shorter decision delay is kept).
// Nor do they take a longer wait to be found again after a spell lost
// (FollowParams::found_confirm_per_lost_s: their improvised cases' frames lost although followed
// doubled). Nor do they set a run of outlier frames aside (FollowParams::outlier_max_s), one
// frame only: the frames a true jump lands on fit the new place less closely than a body's, and
// set aside for 0.05-0.1 s they cost the improvised cases up to 0.7 points within 100 ms on the
// proportioned rig (docs/evaluation.md, "A sensor that pops").
// And they call a place held still for kHeadHandsHeldPlaceLostS lost, not the body's 3 s
// (FollowParams::held_place_lost_s; a shorter one, or 0 for never, stays): a person standing
// with the hands hanging is a take's standing start to three points only. The Bandai dance as
// three points (8.5 s standing first) 95.3 -> 96.9 % lost, the library's, Bandai and
// proportioned rigs' dance cases the same (docs/evaluation.md, "Still where found again").
// `duet follow`, `duet serve` and `duet eval` make their trackers with it.
inline constexpr float kHeadHandsUnexplainedJumpHoldS = 0.3f;
inline constexpr float kHeadHandsOutlierMaxS = 0.0f;
inline constexpr float kHeadHandsHeldPlaceLostS = 2.0f;
FollowParams follow_params_for(InputPoints points, FollowParams params);
// The rig offset's parameters for these input points: three points average it over
// PostureBiasParams::head_hands_time_constant_s (also while the sensor is noisy). FollowSession
// applies it to the parameters it is given.
PostureBiasParams posture_bias_params_for(InputPoints points, PostureBiasParams params);

class DuetLibrary {
 public:
  using Progress = std::function<void(int done, int total, const std::string& what)>;

  // Loads every pair, checks each is a duet (same frame count and rate), extracts and
  // standardises template features and builds the template model. All takes must share one
  // frame rate.
  static Result<DuetLibrary> load(const std::vector<PairFiles>& pairs, const LibraryOptions& options,
                                  const Progress& progress = {});

  const std::vector<DuetTake>& takes() const { return takes_; }
  const TemplateModel& model() const { return *model_; }
  std::shared_ptr<const TemplateModel> model_ptr() const { return model_; }
  const FeatureNormalizer& normalizer() const { return normalizer_; }
  const LibraryOptions& options() const { return options_; }
  double frame_rate() const { return model_->frame_rate_hz(); }
  // Standardised template features of take k, frame f (a row of the model).
  int state_of(int take, int frame) const { return takes_[static_cast<std::size_t>(take)].first_state + frame; }

  // The captured take and frame shown for frame `frame` of the model's take `model_take`: the
  // same for a captured take, the copied take's frame for a copy (LibraryOptions::grow_to_states).
  // {-1, -1} for an invalid model take. Allocates nothing.
  LibraryPlace place_of(int model_take, int frame) const noexcept;
  bool grown() const { return !copy_sources_.empty(); }
  // The beam follower's jump candidate index, when the model cache provided one (else null: the
  // beam builds its own).
  std::shared_ptr<const JumpCandidateIndex> candidate_index() const { return candidate_index_; }
  // Why the model cache was not read (empty when it was, or when there is none); the cache was
  // then rebuilt.
  const std::string& model_cache_note() const { return model_cache_note_; }

  // Three points: where the template dancers' wrists are with both arms held straight forward
  // (arms_forward_of_body, per coordinate the median over takes), which a user's calibration is
  // measured against (FollowSession::set_arms_forward). Zero for full-body features.
  const ArmsForward& template_arms_forward() const { return template_arms_forward_; }

  // An extractor for a user whose motion uses `skeleton` (any convention with the needed
  // roles); its raw output is standardised with normalizer().
  Result<FeatureExtractor> make_extractor(std::shared_ptr<const Skeleton> skeleton,
                                          const JointRoles& roles) const;

 private:
  // What a model cache made for this library is keyed by: its features, takes and growth.
  static std::uint64_t model_key(const FeatureMatrix& features, const std::vector<int>& take_start,
                                 int velocity_dims, const LibraryOptions& options);
  // Grows the captured model (options_.grow_to_states) and reads or writes the model cache.
  Status grow_and_cache(TemplateModel captured, std::uint64_t key);

  std::vector<DuetTake> takes_;
  std::shared_ptr<const TemplateModel> model_;
  FeatureNormalizer normalizer_;
  LibraryOptions options_;
  // Per model take beyond the captured ones (a grown library): what it copies.
  std::vector<SyntheticTakeSource> copy_sources_;
  std::shared_ptr<const JumpCandidateIndex> candidate_index_;
  std::string model_cache_note_;
  ArmsForward template_arms_forward_;
};

}  // namespace duet
