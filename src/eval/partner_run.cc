#include "duet/eval/partner_run.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <map>

#include "duet/live/live_loop.h"
#include "duet/partner/alignment.h"

namespace duet {

namespace {

constexpr std::array<Role, 2> kWrists = {Role::kLeftWrist, Role::kRightWrist};
constexpr std::array<Role, 2> kToes = {Role::kLeftToe, Role::kRightToe};

// Wraps the real tracker: records its results in the first pass, replays them after rewind().
// Its buffer is reserved up front, so step() allocates nothing in either mode.
class ReplayTracker final : public Tracker {
 public:
  ReplayTracker(std::unique_ptr<Tracker> inner, int frames) : inner_(std::move(inner)) {
    recorded_.reserve(static_cast<std::size_t>(frames));
  }
  void reset() noexcept override {
    if (!replaying_) inner_->reset();
    next_ = 0;
  }
  FollowResult step(std::span<const float> features, double dt_s) noexcept override {
    if (replaying_) return next_ < recorded_.size() ? recorded_[next_++] : FollowResult{};
    const FollowResult r = inner_->step(features, dt_s);
    if (recorded_.size() < recorded_.capacity()) recorded_.push_back(r);
    return r;
  }
  std::string_view name() const noexcept override { return inner_->name(); }
  void start_replay() noexcept {
    replaying_ = true;
    next_ = 0;
  }

 private:
  std::unique_ptr<Tracker> inner_;
  std::vector<FollowResult> recorded_;
  std::size_t next_ = 0;
  bool replaying_ = false;
};

double elapsed_us(std::chrono::steady_clock::time_point start,
                  std::chrono::steady_clock::time_point stop) {
  return std::chrono::duration<double, std::micro>(stop - start).count();
}

void load_frame(const Performance& performance, int f, SourceFrame& frame) {
  frame.time_s = performance.times_s[static_cast<std::size_t>(f)];
  frame.arrival = SteadyClock::now();
  std::ranges::copy(performance.motion.translations_ls(f), frame.translations_ls.begin());
  std::ranges::copy(performance.motion.rotations_ls(f), frame.rotations_ls.begin());
}

}  // namespace

std::vector<PartnerConfig> standard_partner_configs(const PartnerParams& base) {
  // Each configuration names the corrections that are on, in parse_corrections()'s syntax.
  static constexpr std::pair<const char*, const char*> kConfigs[] = {
      {"all", "all"},
      {"no-foothold", "align,contact,smooth,footlock,blend"},
      {"no-contact", "align,smooth,footlock,blend,foothold"},
      {"no-footlock", "align,contact,smooth,blend"},
      {"no-blend", "align,contact,smooth,footlock"},
      {"no-smooth", "align,contact,footlock,blend,foothold"},
      {"align-only", "align"},
      {"none", "none"}};
  std::vector<PartnerConfig> configs;
  for (const auto& [name, corrections] : kConfigs) {
    PartnerParams params = base;
    const Status parsed = parse_corrections(corrections, params);
    assert(parsed.ok() && "the list above names only known corrections");
    (void)parsed;
    configs.push_back({name, params});
  }
  return configs;
}

Result<PartnerPerformanceResult> run_partner_performance(const DuetLibrary& library,
                                                         const Performance& performance,
                                                         std::unique_ptr<Tracker> tracker,
                                                         std::span<const PartnerConfig> configs,
                                                         const PartnerMetricsOptions& options) {
  const int frames = performance.frame_count();
  if (frames == 0) return Error{"partner metrics: the performance has no frames"};
  if (configs.empty()) return Error{"partner metrics: no configuration to run"};
  const int takes = static_cast<int>(library.takes().size());
  for (const TruthFrame& t : performance.truth) {
    if (t.take < 0 || t.take >= takes) {
      return Error{"partner metrics: the performance's truth names take " + std::to_string(t.take) +
                   ", not in the library"};
    }
  }

  auto replay = std::make_unique<ReplayTracker>(std::move(tracker), frames);
  ReplayTracker* replay_ptr = replay.get();  // owned by the loop below
  // LiveLoop shares its library; this one is the caller's and outlives the loop (no owner).
  const std::shared_ptr<const DuetLibrary> shared(std::shared_ptr<const DuetLibrary>(), &library);
  const SourceSkeleton user{performance.motion.skeleton_ptr(),
                            performance.roles,
                            1.0,
                            performance.motion.frame_rate(),
                            performance.told_head_height_m,
                            performance.told_arms_forward};
  Result<LiveLoop> created = LiveLoop::create(shared, user, std::move(replay), configs[0].params);
  if (!created) return Error{"partner metrics: " + created.error().message};
  LiveLoop& loop = created.value();

  SourceFrame frame;
  frame.resize(performance.motion.joint_count());
  PartnerPerformanceResult result;

  // Recording pass: the real tracker, the whole loop timed.
  double total_us = 0.0;
  for (int f = 0; f < frames; ++f) {
    load_frame(performance, f, frame);
    const auto start = std::chrono::steady_clock::now();
    loop.step(frame);
    total_us += elapsed_us(start, std::chrono::steady_clock::now());
  }
  result.loop_step_us = total_us / frames;
  replay_ptr->start_replay();

  // The truth's takes: their captured duets (for the true response) and the references.
  std::map<int, CapturedDuetSampler> samplers;
  CapturedReference reference;
  for (const TruthFrame& t : performance.truth) {
    if (samplers.contains(t.take)) continue;
    const DuetTake& take = library.takes()[static_cast<std::size_t>(t.take)];
    const PartnerModel& model = loop.partner_model(t.take);
    samplers.emplace(t.take,
                     CapturedDuetSampler(take.template_motion.clip, take.template_motion.roles,
                                         take.response_motion.clip, model));
    add_captured_reference(
        take.response_motion.clip, take.response_motion.roles,
        {model.foot_ground_height(Side::kLeft), model.foot_ground_height(Side::kRight)}, options,
        reference);
  }

  const Skeleton& partner_skeleton = *loop.partner_skeleton();
  const auto partner_joints = static_cast<std::size_t>(partner_skeleton.joint_count());
  std::vector<Quat> previous_rotations(partner_joints, Quat::Identity());
  std::vector<Quat> previous_true_rotations(partner_joints, Quat::Identity());
  std::vector<PartnerFrameRecord> records(static_cast<std::size_t>(frames));
  JerkMeter jerk(partner_joints), true_jerk(partner_joints);
  const double nominal_period = 1.0 / performance.motion.frame_rate();
  FootLockParams planted;  // what a planted foot is for the slide metric (not the lock's own)
  planted.height_margin_m = options.slip.height_margin_m;
  planted.speed_threshold_mps = options.planted_speed_mps;
  for (const PartnerConfig& config : configs) {
    loop.set_params(config.params);
    loop.reset();  // rewinds the replay too
    std::array<Vec3, 2> previous_toes{Vec3::Zero(), Vec3::Zero()};
    jerk.reset();
    true_jerk.reset();
    for (int f = 0; f < frames; ++f) {
      const auto fs = static_cast<std::size_t>(f);
      load_frame(performance, f, frame);
      const auto start = std::chrono::steady_clock::now();
      const LiveOutput& out = loop.step(frame);
      const auto stop = std::chrono::steady_clock::now();

      PartnerFrameRecord& r = records[fs];
      r = PartnerFrameRecord{};
      r.step_us = elapsed_us(start, stop);
      const TruthFrame& truth = performance.truth[fs];
      CapturedDuetSampler& sampler = samplers.at(truth.take);
      // The user's heading: the sensed body's, or the real body's for three points and for a
      // sensor that stalls (Performance::true_headings_ws).
      const Transform user_heading =
          performance.true_headings_ws.empty()
              ? body_heading_frame(out.user_positions_ws, performance.roles)
              : performance.true_headings_ws[fs];
      // The true response where the partner would stand for this user: the spacing fitted to the
      // body the partner was fitted to (a 1.1x body's partner stands 5 % further away).
      const PartnerModel& true_model = loop.partner_model(truth.take);
      sampler.compute(truth.template_frame, user_heading,
                      true_model.spacing_scale(loop.user_height_m()));
      r.user_distance_m =
          horizontal_distance(out.partner_positions_ws[0], user_heading.translation);
      r.true_user_distance_m =
          horizontal_distance(sampler.placed_positions_ws()[0], user_heading.translation);
      r.spacing_error_m = std::abs(r.user_distance_m - r.true_user_distance_m);
      r.joint_error_m =
          mean_joint_distance_m(out.partner_positions_ws, sampler.placed_positions_ws());

      const PartnerModel& model = loop.partner_model(out.partner_take);
      const int true_frame = std::clamp(static_cast<int>(std::lround(truth.template_frame)), 0,
                                        true_model.frame_count() - 1);
      const JointRoles& partner_roles = model.response_roles();
      for (int pair = 0; pair < kHandPairCount; ++pair) {
        if ((sampler.contact_mask() & (1u << pair)) == 0) continue;
        const int pw = partner_roles[kWrists[static_cast<std::size_t>(response_side(pair))]];
        const int uw = performance.roles[kWrists[static_cast<std::size_t>(template_side(pair))]];
        if (pw < 0 || uw < 0) continue;
        const Vec3& partner_wrist = out.partner_positions_ws[static_cast<std::size_t>(pw)];
        const Vec3& sensed_wrist = out.user_positions_ws[static_cast<std::size_t>(uw)];
        const Vec3& real_wrist =
            performance.true_wrists_ws.empty()
                ? sensed_wrist
                : performance.true_wrists_ws[fs][static_cast<std::size_t>(template_side(pair))];
        const double captured = sampler.captured_wrist_distance_m(pair);
        r.hand_error_m[static_cast<std::size_t>(pair)] =
            std::abs((partner_wrist - real_wrist).norm() - captured);
        r.sensed_hand_error_m[static_cast<std::size_t>(pair)] =
            std::abs((partner_wrist - sensed_wrist).norm() - captured);
        r.hand_pairs |= static_cast<std::uint8_t>(1u << pair);
        r.hands_joined = r.hands_joined && r.hand_error_m[static_cast<std::size_t>(pair)] <=
                                               options.rejoin_tolerance_m;
      }

      std::array<Vec3, 2> toes;
      for (std::size_t side = 0; side < 2; ++side) {
        toes[side] = out.partner_positions_ws[static_cast<std::size_t>(partner_roles[kToes[side]])];
      }
      // Speeds over at least one nominal sensor period: a late frame followed by an early one
      // (timestamps 1 ms apart) is shown at the next display refresh, not 1 ms later.
      const double dt =
          f > 0 ? std::max(performance.times_s[fs] - performance.times_s[fs - 1], nominal_period)
                : 0.0;
      r.jerk_mps3 = jerk.add(out.partner_positions_ws, dt);
      if (truth.jump) true_jerk.reset();  // the true response is cut at a true jump
      r.true_jerk_mps3 = true_jerk.add(sampler.placed_positions_ws(), dt);
      if (f > 0) {
        for (std::size_t side = 0; side < 2; ++side) {
          const double ground = model.foot_ground_height(static_cast<Side>(side));
          r.slip = r.slip || foot_slips(previous_toes[side], toes[side], ground, dt, options.slip);
          if (foot_near_ground(previous_toes[side], toes[side], ground, options.slip)) {
            const double speed = horizontal_speed_mps(previous_toes[side], toes[side], dt);
            r.ground_speed_sum_mps += speed;
            ++r.ground_feet;
            if (true_model.foot_planted(true_frame, static_cast<Side>(side), planted)) {
              r.planted_slide_mps = std::max(r.planted_slide_mps, speed);
            }
          }
        }
        r.max_angular_speed_rad_s = max_joint_angular_speed_rad_s(
            partner_skeleton, previous_rotations, out.partner_rotations_ls, dt);
        if (!truth.jump) {  // the true response is cut at a true jump
          r.true_max_angular_speed_rad_s = max_joint_angular_speed_rad_s(
              partner_skeleton, previous_true_rotations, sampler.placed_rotations_ls(), dt);
        }
      }
      std::ranges::copy(sampler.placed_rotations_ls(), previous_true_rotations.begin());
      previous_toes = toes;
      std::ranges::copy(out.partner_rotations_ls, previous_rotations.begin());
    }
    PartnerMetricsAccumulator accumulator(options);
    accumulator.add(performance, records);
    accumulator.add_reference(reference);
    result.configs.push_back(std::move(accumulator));
  }
  return result;
}

}  // namespace duet
