#include "duet/live/duet_library.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "duet/base/content_hash.h"
#include "duet/follow/copy_places.h"
#include "duet/follow/model_cache.h"
#include "duet/io/motion_argument.h"
#include "duet/motion/head_hands.h"

namespace duet {

bool parse_dancer_role(const std::string& text, DancerRole& role) {
  if (text == "leader") {
    role = DancerRole::kLeader;
    return true;
  }
  if (text == "partner") {
    role = DancerRole::kPartner;
    return true;
  }
  return false;
}

const char* dancer_role_name(DancerRole role) {
  return role == DancerRole::kLeader ? "leader" : "partner";
}

namespace {

// The motion file names the take: the .bvh, or the .amc of an ASF+AMC pair (not the skeleton).
std::string take_name_of(const MotionFiles& files) {
  for (const std::string& file : files) {
    const std::filesystem::path p(file);
    if (p.extension() != ".asf" && p.extension() != ".ASF") return p.stem().string();
  }
  return files.empty() ? std::string() : std::filesystem::path(files[0]).stem().string();
}

Status check_duet(const std::string& what, LoadedMotion& leader, LoadedMotion& partner,
                  bool trim_to_shorter) {
  if (std::abs(leader.clip.frame_rate() - partner.clip.frame_rate()) > 1e-9) {
    return Error{what + ": the two dancers have different frame rates (" +
                 std::to_string(leader.clip.frame_rate()) + " and " +
                 std::to_string(partner.clip.frame_rate()) + " fps)"};
  }
  const int frames = std::min(leader.clip.frame_count(), partner.clip.frame_count());
  if (leader.clip.frame_count() != partner.clip.frame_count()) {
    if (!trim_to_shorter) {
      return Error{what + ": the two dancers have different frame counts (" +
                   std::to_string(leader.clip.frame_count()) + " and " +
                   std::to_string(partner.clip.frame_count()) +
                   "); a duet is captured together (use --trim to cut to the shorter)"};
    }
    for (LoadedMotion* m : {&leader, &partner}) m->clip.keep_first_frames(frames);
  }
  if (frames < 3) return Error{what + ": a duet needs at least 3 frames"};
  return Ok{};
}

}  // namespace

Result<DuetLibrary> DuetLibrary::load(const std::vector<PairFiles>& pairs,
                                      const LibraryOptions& options, const Progress& progress) {
  if (pairs.empty()) return Error{"no duet given (--pair LEADER PARTNER or --library FILE)"};
  DuetLibrary library;
  library.options_ = options;
  std::vector<FeatureMatrix> raw_features;
  std::vector<ArmsForward> template_arms;  // three points: per take
  int total_frames = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const PairFiles& pair = pairs[k];
    const std::string leader_word = join_motion_argument(pair.leader);
    const std::string partner_word = join_motion_argument(pair.partner);
    if (progress) progress(static_cast<int>(k), static_cast<int>(pairs.size()), leader_word);
    Result<LoadedMotion> leader = load_motion(pair.leader, options.load);
    if (!leader) return leader.error();
    // The two dancers share one capture volume: the partner's file is in the leader's world.
    MotionLoadOptions partner_load = options.load;
    if (!partner_load.up_axis) {
      partner_load.up_axis = leader.value().up_axis;
      partner_load.level = leader.value().level;
    }
    Result<LoadedMotion> partner = load_motion(pair.partner, partner_load);
    if (!partner) return partner.error();
    const std::string what =
        "pair " + std::to_string(k + 1) + " (" + leader_word + ", " + partner_word + ")";
    if (Status ok = check_duet(what, leader.value(), partner.value(), options.trim_to_shorter);
        !ok) {
      return ok.error();
    }
    DuetTake take;
    take.name = pair.name.empty() ? take_name_of(pair.leader) : pair.name;
    const bool user_leads = options.role == DancerRole::kLeader;
    take.template_motion = std::move(user_leads ? leader.value() : partner.value());
    take.response_motion = std::move(user_leads ? partner.value() : leader.value());
    take.first_state = total_frames;
    if (!library.takes_.empty() &&
        std::abs(take.template_motion.clip.frame_rate() -
                 library.takes_[0].template_motion.clip.frame_rate()) > 1e-9) {
      return Error{what + ": every duet in a library must have the same frame rate"};
    }
    Result<FeatureExtractor> extractor = FeatureExtractor::create(
        take.template_motion.clip.skeleton_ptr(), take.template_motion.roles, options.features);
    if (!extractor) return Error{what + ": " + extractor.error().message};
    if (options.features.input_points == InputPoints::kHeadHands) {
      Result<Quat> head = head_correction(take.template_motion.clip, take.template_motion.roles);
      if (!head) return Error{what + ": " + head.error().message};
      extractor.value().set_head_correction(head.value());
      // Every 10th frame: a median of places the collar bones and the head barely move.
      constexpr int kArmsStride = 10;
      Result<ArmsForward> arms = arms_forward_of_body(
          take.template_motion.clip, take.template_motion.roles, head.value(), kArmsStride);
      if (!arms) return Error{what + ": " + arms.error().message};
      template_arms.push_back(arms.value());
    }
    raw_features.push_back(extractor.value().extract_clip(take.template_motion.clip));
    total_frames += take.template_motion.clip.frame_count();
    library.takes_.push_back(std::move(take));
  }
  if (progress)
    progress(static_cast<int>(pairs.size()), static_cast<int>(pairs.size()), "features");

  FeatureMatrix all(total_frames, options.features.dimension());
  std::vector<int> take_start;
  for (std::size_t k = 0; k < raw_features.size(); ++k) {
    const int first = library.takes_[k].first_state;
    all.middleRows(first, raw_features[k].rows()) = raw_features[k];
    take_start.push_back(first);
  }
  if (!template_arms.empty()) library.template_arms_forward_ = median_arms_forward(template_arms);
  library.normalizer_ = FeatureNormalizer::fit(all, options.features);
  library.normalizer_.apply(all);
  // The feature vector ends with its velocity blocks (root velocity, effector speed).
  const int velocity_dims = options.features.velocity_dims();
  const std::uint64_t key = model_key(all, take_start, velocity_dims, options);
  Result<TemplateModel> model =
      TemplateModel::build(std::move(all), std::move(take_start),
                           library.takes_[0].template_motion.clip.frame_rate(), velocity_dims);
  if (!model) return model.error();
  if (Status grown = library.grow_and_cache(std::move(model).value(), key); !grown) {
    return grown.error();
  }
  return library;
}

std::uint64_t DuetLibrary::model_key(const FeatureMatrix& features,
                                     const std::vector<int>& take_start, int velocity_dims,
                                     const LibraryOptions& options) {
  std::uint64_t key =
      content_hash(features.data(), static_cast<std::size_t>(features.size()) * sizeof(float));
  key = content_hash(take_start.data(), take_start.size() * sizeof(int), key);
  const std::int64_t shape[] = {features.rows(), features.cols(), velocity_dims,
                                options.grow_to_states, options.grow_seed};
  return content_hash(shape, sizeof(shape), key);
}

Status DuetLibrary::grow_and_cache(TemplateModel captured, std::uint64_t key) {
  const int captured_states = captured.num_states();
  SyntheticLibraryOptions grow;
  grow.num_states = options_.grow_to_states;
  grow.seed = options_.grow_seed;
  grow.keep_real_takes = true;
  if (options_.grow_to_states != 0) {
    if (options_.grow_to_states < captured_states) {
      return Error{"the library cannot grow to " + std::to_string(options_.grow_to_states) +
                   " states: its takes already have " + std::to_string(captured_states)};
    }
    Result<std::vector<SyntheticTakeSource>> sources = synthetic_take_sources(captured, grow);
    if (!sources) return sources.error();
    copy_sources_.assign(sources.value().begin() + captured.num_takes(), sources.value().end());
  }
  auto build = [&]() -> Result<TemplateModel> {
    if (options_.grow_to_states == 0) return captured;
    return synthesize_library(captured, grow);
  };
  // The limbs the emission bounds (FeatureSpec::limb_dims), and a grown library's confidence
  // counts every copy of a moment (copy_places.h). Neither is in the model cache.
  const auto finish_model = [&](TemplateModel model) -> Result<TemplateModel> {
    if (Status limbs = model.set_limbs(options_.features.limb_dims()); !limbs) {
      return limbs.error();
    }
    if (copy_sources_.empty()) return model;
    Result<CopyPlaces> places = CopyPlaces::build(model, captured.num_takes(), copy_sources_);
    if (!places) return places.error();
    model.set_copy_places(std::make_shared<const CopyPlaces>(std::move(places).value()));
    return model;
  };
  if (options_.model_cache.empty()) {
    Result<TemplateModel> model = build();
    if (!model) return model.error();
    Result<TemplateModel> placed = finish_model(std::move(model).value());
    if (!placed) return placed.error();
    model_ = std::make_shared<const TemplateModel>(std::move(placed).value());
  } else {
    Result<CachedModel> cached =
        load_or_build_model_cache(options_.model_cache, key, build, &model_cache_note_);
    if (!cached) return cached.error();
    Result<TemplateModel> placed = finish_model(std::move(cached.value().model));
    if (!placed) return placed.error();
    model_ = std::make_shared<const TemplateModel>(std::move(placed).value());
    candidate_index_ = std::make_shared<const JumpCandidateIndex>(std::move(cached.value().index));
  }
  const std::size_t takes = takes_.size() + copy_sources_.size();
  if (static_cast<std::size_t>(model_->num_takes()) != takes) {
    return Error{"the library model has " + std::to_string(model_->num_takes()) + " takes where " +
                 std::to_string(takes) + " were expected"};
  }
  return Ok{};
}

LibraryPlace DuetLibrary::place_of(int model_take, int frame) const noexcept {
  const int captured = static_cast<int>(takes_.size());
  if (model_take < 0 || frame < 0) return {};
  if (model_take < captured) return {model_take, frame};
  const auto copy = static_cast<std::size_t>(model_take - captured);
  if (copy >= copy_sources_.size()) return {};
  const SyntheticTakeSource& source = copy_sources_[copy];
  return {source.real_take, source.real_frame(frame)};
}

Result<FeatureExtractor> DuetLibrary::make_extractor(std::shared_ptr<const Skeleton> skeleton,
                                                     const JointRoles& roles) const {
  return FeatureExtractor::create(std::move(skeleton), roles, options_.features);
}

FollowParams follow_params_for(InputPoints points, FollowParams params) {
  if (points == InputPoints::kHeadHands) {
    params.unexplained_jump_hold_s = kHeadHandsUnexplainedJumpHoldS;
    params.found_confirm_per_lost_s = 0.0f;
    params.outlier_max_s = kHeadHandsOutlierMaxS;
    if (params.held_place_lost_s > kHeadHandsHeldPlaceLostS) {
      params.held_place_lost_s = kHeadHandsHeldPlaceLostS;
    }
  }
  return params;
}

PostureBiasParams posture_bias_params_for(InputPoints points, PostureBiasParams params) {
  if (points == InputPoints::kHeadHands) {
    params.time_constant_s = params.head_hands_time_constant_s;
    params.noisy_time_constant_s = std::max(params.noisy_time_constant_s, params.time_constant_s);
  }
  return params;
}

}  // namespace duet
