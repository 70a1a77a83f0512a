// A library of duets (method.md 1): captured pairs, the user's role, and everything built from
// them offline for following: per-take template and response clips, template features
// standardised over the whole library, and the follower's template model.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_extractor.h"
#include "duet/follow/template_model.h"
#include "duet/io/motion_file.h"

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
};

struct DuetTake {
  std::string name;  // PairFiles::name, else the leader's motion file stem, e.g. "60_01_scaled"
  LoadedMotion template_motion;
  LoadedMotion response_motion;
  int first_state = 0;  // index of this take's frame 0 among all template states
};

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

  // An extractor for a user whose motion uses `skeleton` (any convention with the needed
  // roles); its raw output is standardised with normalizer().
  Result<FeatureExtractor> make_extractor(std::shared_ptr<const Skeleton> skeleton,
                                          const JointRoles& roles) const;

 private:
  std::vector<DuetTake> takes_;
  std::shared_ptr<const TemplateModel> model_;
  FeatureNormalizer normalizer_;
  LibraryOptions options_;
};

}  // namespace duet
