#include "duet/eval/runner.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>

#include "duet/eval/look_alike_frames.h"
#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "duet/live/follow_session.h"
#include "duet/math/rotation.h"

namespace duet {

std::vector<EvalCase> standard_cases(const CaseSettings& settings) {
  std::vector<EvalCase> cases;
  auto add = [&](std::string name, std::string description) -> EvalCase& {
    EvalCase c;
    c.name = std::move(name);
    c.description = std::move(description);
    c.recipe.improvise_options.duration_s = settings.improvise_duration_s;
    cases.push_back(std::move(c));
    return cases.back();
  };
  const SensorNoiseOptions noise{settings.noise_rotation_deg, settings.noise_position_m, 0};
  const FrameLossOptions loss{0.10, 0.20, 1.5, 0.002, 0};

  add("clean", "the take as captured");
  add("tempo-slow", "the whole take at 0.7x tempo").recipe.play.tempo.factor = 0.7;
  add("tempo-fast", "the whole take at 1.4x tempo").recipe.play.tempo.factor = 1.4;
  {
    EvalCase& c = add("drift", "tempo drifting smoothly between 0.8x and 1.3x (12 s period)");
    c.recipe.play.tempo.drift_low = 0.8;
    c.recipe.play.tempo.drift_high = 1.3;
  }
  add("improv", "2-5 s segments of the take replayed in another order, no pause").recipe.improvise =
      true;
  {
    EvalCase& c = add("improv-pause", "improv with a 0.3-0.8 s hold (tiny sway) before each jump");
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
  }
  {
    EvalCase& c =
        add("improv-library", "improv-pause with segments from every take of the library");
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.across_takes = true;
  }
  add("noise", "sensor noise: rotations (RMS per joint) and root position").recipe.noise = noise;
  {
    EvalCase& c = add("30hz-noisy", "a 30 Hz sensor with the noise");
    c.recipe.play.rate_hz = settings.low_rate_hz;
    c.recipe.noise = noise;
  }
  add("late-frames",
      "10% of frames dropped (bursts of 1-3), 20% late by up to 1.5 periods, "
      "2 ms jitter")
      .recipe.loss = loss;
  add("body-size", "a bigger dancer: skeleton and root path scaled").recipe.body_scale =
      settings.body_scale;
  {
    EvalCase& c =
        add("room-place", "another place and facing: turned 135 deg, moved (2.5, -1.5) m");
    c.recipe.room_yaw_rad = deg_to_rad(135.0);
    c.recipe.room_offset_m = Vec3(2.5, 0.0, -1.5);
  }
  add("partner-role", "the user dances the partner (library built with role=partner)")
      .partner_role = true;
  {
    EvalCase& c =
        add("improv-30hz-noisy", "improv-pause at 30 Hz with the noise and late/dropped frames");
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.recipe.improvise_options.rate_hz = settings.low_rate_hz;
    c.recipe.noise = noise;
    c.recipe.loss = loss;
  }
  {
    // Issue 11's harsher sensor, fixed (not scaled by the settings): per-axis noise is
    // rotation_deg / sqrt(3) (with_sensor_noise takes the RMS angle).
    EvalCase& c = add("harsh",
                      "improv-pause at 30 Hz, 4 deg per axis + 1 cm root noise, 3% repeated "
                      "frames, a 1.1x body");
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.recipe.improvise_options.rate_hz = 30.0;
    c.recipe.noise = {4.0 * std::sqrt(3.0), 0.01, 0};
    c.recipe.loss.repeat_fraction = 0.03;
    c.recipe.body_scale = 1.1;
  }
  {
    // A suit faster than the template (Perception Neuron, Xsens, Rokoko run at 100-240 Hz): more
    // frames than template frames, each with its own noise.
    EvalCase& c = add("120hz-noisy", "a 120 Hz sensor with the noise");
    c.recipe.play.rate_hz = 120.0;
    c.recipe.noise = noise;
  }
  {
    // A learner on a fast suit (Xsens, Rokoko: 240 Hz): slower than the template, at four steps
    // a template frame of time, 0.175 template frames a step.
    EvalCase& c = add("240hz-slow", "a 240 Hz sensor with the noise, the dancer at 0.7x tempo");
    c.recipe.play.rate_hz = 240.0;
    c.recipe.play.tempo.factor = 0.7;
    c.recipe.noise = noise;
  }
  {
    // A sensor that loses the dancer now and then: a suit's occluded markers, a controller out of
    // the headset's view. The dancer dances on through the loss.
    EvalCase& c = add("dropouts", "the take with the noise, tracking lost for 0.3-1 s every 8 s");
    c.recipe.noise = noise;
    c.recipe.loss.gap_every_s = 8.0;
  }
  {
    // A sensor that stalls now and then: a driver or a network stream that stops updating, a
    // headset that lost tracking and reports its last pose. The dancer dances on.
    EvalCase& c = add("stalls",
                      "the take with the noise, the sensor holding its last pose for 0.3-2 s "
                      "every 8 s (a stalled stream, a headset that lost tracking); three points: "
                      "also one controller held 0.3-2 s every 6 s (out of the headset's view)");
    c.recipe.noise = noise;
    c.recipe.loss.freeze_every_s = 8.0;
    c.recipe.point_noise.stall_every_s = 6.0;
  }
  {
    // An inertial suit's slow errors: every joint off by its calibration and drifting, as
    // SensorNoiseOptions describes; the white noise on top.
    EvalCase& c = add("suit-drift", fmt::format("an inertial suit: every joint off by {:g} deg of "
                                                "calibration and {:g} deg of drift (10 s), with "
                                                "the noise",
                                                settings.suit_bias_deg, settings.suit_drift_deg));
    c.recipe.noise = noise;
    c.recipe.noise.bias_deg = settings.suit_bias_deg;
    c.recipe.noise.drift_deg = settings.suit_drift_deg;
  }
  {
    // A camera pitched down (a depth camera on a shelf, a phone for a pose estimator) sees a
    // tilted floor; the performance is levelled as loading a file levels it (level_as_loaded).
    EvalCase& c = add("tilted", fmt::format("the noise, in a world tilted by {:g} deg (a camera "
                                            "pitched down), levelled as a loaded file is",
                                            settings.tilt_deg));
    c.recipe.noise = noise;
    c.recipe.world_tilt_deg = settings.tilt_deg;
  }
  {
    // An optical system in a couple dance: the partner's body hides one of the dancer's arms now
    // and then, and the live solver holds the arm where it last saw it (SensorNoiseOptions).
    EvalCase& c = add("occluded",
                      "the take with the noise, one arm held where last seen for "
                      "0.3-1.5 s every 6 s (markers hidden by the partner)");
    c.recipe.noise = noise;
    c.recipe.noise.occlusion_every_s = 6.0;
  }
  {
    // Pops: a joint the tracker gets grossly wrong for a frame or a few (a marker swap, a flipped
    // limb, a magnetic disturbance; three points: a controller reported elsewhere).
    EvalCase& c = add("glitches",
                      "the take with the noise, one joint turned 30-90 deg for 1-3 frames every "
                      "2 s (a marker swap, a flipped limb); three points: also one controller "
                      "reported 10-40 cm off for 1-3 frames every 2 s");
    c.recipe.noise = noise;
    c.recipe.noise.glitch_every_s = 2.0;
    c.recipe.point_noise.glitch_every_s = 2.0;
  }
  // Describe the magnitudes actually used.
  for (EvalCase& c : cases) {
    if (c.name == "harsh") continue;
    if (c.recipe.noise.active()) {
      c.description += fmt::format(" (noise {:g} deg, {:g} cm)", settings.noise_rotation_deg,
                                   settings.noise_position_m * 100.0);
    }
  }
  return cases;
}

std::vector<EvalCase> noise_sweep_cases() {
  std::vector<EvalCase> cases;
  for (int deg = 0; deg <= 5; ++deg) {
    EvalCase c;
    c.name = fmt::format("noise-sweep-{}", deg);
    c.description = fmt::format("improv-pause with {} deg per axis{} of sensor noise", deg,
                                deg > 0 ? " + 1 cm root" : "");
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    // with_sensor_noise takes the RMS angle: sqrt(3) times the per-axis deviation.
    c.recipe.noise = {deg * std::sqrt(3.0), deg > 0 ? 0.01 : 0.0, 0};
    cases.push_back(std::move(c));
  }
  return cases;
}

std::vector<EvalCase> suit_sweep_cases(const CaseSettings& settings) {
  std::vector<EvalCase> cases;
  for (int deg = 0; deg <= 10; deg += 2) {
    EvalCase c;
    c.name = fmt::format("suit-sweep-{}", deg);
    c.description = fmt::format(
        "suit-drift with {} deg of calibration and {} deg of drift per "
        "joint (noise {:g} deg, {:g} cm)",
        deg, deg, settings.noise_rotation_deg, settings.noise_position_m * 100.0);
    c.recipe.noise = {settings.noise_rotation_deg, settings.noise_position_m, 0};
    c.recipe.noise.bias_deg = deg;
    c.recipe.noise.drift_deg = deg;
    cases.push_back(std::move(c));
  }
  return cases;
}

std::vector<EvalCase> body_sweep_cases(const CaseSettings& settings) {
  std::vector<EvalCase> cases;
  for (int percent = 80; percent <= 120; percent += 10) {
    EvalCase c;
    c.name = fmt::format("body-sweep-{}", percent);
    c.description = fmt::format("improv-pause danced by a {:g}x body (noise {:g} deg, {:g} cm)",
                                percent / 100.0, settings.noise_rotation_deg,
                                settings.noise_position_m * 100.0);
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.recipe.noise = {settings.noise_rotation_deg, settings.noise_position_m, 0};
    c.recipe.body_scale = percent / 100.0;
    cases.push_back(std::move(c));
  }
  return cases;
}

std::vector<EvalCase> rate_sweep_cases(const CaseSettings& settings) {
  std::vector<EvalCase> cases;
  // A phone's pose estimator (20-30 Hz), a webcam (25), PAL video (50), the salsa's own 60, VR
  // headsets (72, 90, 120), inertial suits (100-240).
  for (const int hz : {20, 25, 30, 50, 60, 72, 90, 120, 240}) {
    EvalCase c;
    c.name = fmt::format("rate-sweep-{}", hz);
    c.description = fmt::format("improv-pause from a {} Hz sensor (noise {:g} deg, {:g} cm)", hz,
                                settings.noise_rotation_deg, settings.noise_position_m * 100.0);
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.recipe.improvise_options.rate_hz = hz;
    c.recipe.noise = {settings.noise_rotation_deg, settings.noise_position_m, 0};
    cases.push_back(std::move(c));
  }
  return cases;
}

std::vector<EvalCase> tempo_sweep_cases(const CaseSettings& settings) {
  std::vector<EvalCase> cases;
  // A learner at half the music's tempo to a dancer well ahead of the capture.
  for (const int percent : {50, 60, 70, 85, 100, 120, 140, 160}) {
    EvalCase c;
    c.name = fmt::format("tempo-sweep-{}", percent);
    c.description =
        fmt::format("improv-pause danced at {:g}x tempo (noise {:g} deg, {:g} cm)", percent / 100.0,
                    settings.noise_rotation_deg, settings.noise_position_m * 100.0);
    c.recipe.improvise = true;
    c.recipe.improvise_options.pause_prob = 1.0;
    c.recipe.improvise_options.tempo.factor = percent / 100.0;
    c.recipe.noise = {settings.noise_rotation_deg, settings.noise_position_m, 0};
    cases.push_back(std::move(c));
  }
  return cases;
}

std::vector<EvalCase> cases_on_rigs(const std::vector<EvalCase>& cases,
                                    const std::vector<EvalRig>& rigs) {
  std::vector<EvalCase> out;
  for (const EvalRig& rig : rigs) {
    for (const EvalCase& base : cases) {
      EvalCase c = base;
      if (rig.skeleton) {
        c.name = base.name + "@" + rig.name;
        c.seed_name = base.seed_key();
        c.description = base.description + ", on the " + rig.name + " rig";
        c.recipe.rig = rig.skeleton;
        c.recipe.rig_roles = rig.roles;
        c.recipe.rig_name = rig.name;
      }
      out.push_back(std::move(c));
    }
  }
  return out;
}

namespace {

struct KindName {
  TrackerKind kind;
  std::string_view name;
};
constexpr KindName kKindNames[] = {{TrackerKind::kHmm, "hmm"},
                                   {TrackerKind::kHmmPaper, "hmm-paper"},
                                   {TrackerKind::kLeftToRight, "left-to-right"},
                                   {TrackerKind::kNearestNeighbour, "nearest"},
                                   {TrackerKind::kOnlineDtw, "online-dtw"},
                                   {TrackerKind::kNaiveHmm, "naive-hmm"}};

template <typename T>
Result<std::unique_ptr<Tracker>> boxed(Result<T> tracker) {
  if (!tracker) return tracker.error();
  return std::unique_ptr<Tracker>(std::make_unique<T>(std::move(tracker).value()));
}

// FNV-1a: a seed per case name that does not depend on which cases run.
std::uint64_t name_hash(std::string_view name) {
  std::uint64_t h = 1469598103934665603ull;
  for (const char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

// A tracker that only lets the session compute features (for the naive comparison, which runs
// the trackers on a one-take model outside the session).
class NullTracker final : public Tracker {
 public:
  void reset() noexcept override {}
  FollowResult step(std::span<const float>, double) noexcept override { return {}; }
  std::string_view name() const noexcept override { return "null"; }
};

struct Timed {
  FollowResult result;
  double us;
};

template <typename F>
Timed timed(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  FollowResult r = f();
  const auto stop = std::chrono::steady_clock::now();
  return {r, std::chrono::duration<double, std::micro>(stop - start).count()};
}

FrameEstimate to_estimate(const FollowResult& r, double us) { return frame_estimate(r, us); }

std::vector<SourceTake> sources_for(const DuetLibrary& library, int take, bool across_takes) {
  std::vector<SourceTake> sources;
  auto add = [&](int k) {
    const DuetTake& t = library.takes()[static_cast<std::size_t>(k)];
    sources.push_back({k, &t.template_motion.clip, t.template_motion.roles});
  };
  add(take);
  if (across_takes) {
    for (int k = 0; k < static_cast<int>(library.takes().size()); ++k) {
      if (k != take) add(k);
    }
  }
  return sources;
}

Result<NaiveCheck> run_naive_check(const DuetLibrary& library, const EvalCase& eval_case, int take,
                                   const EvalOptions& options) {
  NaiveCheck check;
  check.take = take;
  check.take_name = library.takes()[static_cast<std::size_t>(take)].name;
  check.case_name = eval_case.name;
  const TemplateModel& full = library.model();
  const int begin = full.take_begin(take), count = full.take_end(take) - begin;
  if (count > NaiveHmmFollower::kMaxStates) {
    return Error{"naive-hmm: take " + check.take_name + " has " + std::to_string(count) +
                 " states, more than the naive forward's limit " +
                 std::to_string(NaiveHmmFollower::kMaxStates)};
  }
  Result<TemplateModel> one =
      TemplateModel::build(FeatureMatrix(full.features().middleRows(begin, count)), {},
                           full.frame_rate_hz(), full.velocity_dims());
  if (!one) return one.error();
  if (Status limbs = one.value().set_limbs(full.limbs()); !limbs) return limbs.error();
  const TemplateModel& model = one.value();
  check.states = model.num_states();

  const std::vector<SourceTake> sources = sources_for(library, take, false);
  Result<Performance> made = make_performance(
      sources, eval_case.recipe,
      derive_seed(options.seed, name_hash(eval_case.seed_key()), static_cast<std::uint64_t>(take)));
  if (!made) return made.error();
  const Performance& performance = made.value();

  Result<FollowSession> session =
      FollowSession::create(library, performance.motion.skeleton_ptr(), performance.roles,
                            std::make_unique<NullTracker>());
  if (!session) return session.error();
  Result<HmmFollower> fast = HmmFollower::create(model, options.hmm);
  if (!fast) return fast.error();
  Result<NaiveHmmFollower> naive = NaiveHmmFollower::create(model, options.hmm);
  if (!naive) return naive.error();

  std::vector<FrameEstimate> fast_estimates, naive_estimates;
  std::vector<float> features;
  for (int f = 0; f < performance.frame_count(); ++f) {
    const auto fs = static_cast<std::size_t>(f);
    session.value().step(performance.motion.translations_ls(f), performance.motion.rotations_ls(f),
                         performance.times_s[fs]);
    const std::span<const float> phi = session.value().last_features();
    const double dt = f == 0 ? 0.0 : performance.times_s[fs] - performance.times_s[fs - 1];
    const Timed a = timed([&] { return fast.value().step(phi, dt); });
    const Timed b = timed([&] { return naive.value().step(phi, dt); });
    check.same_state += a.result.state == b.result.state ? 1 : 0;
    ++check.frames;
    FrameEstimate ea = to_estimate(a.result, a.us), eb = to_estimate(b.result, b.us);
    // The one-take model's take 0 is the library's take `take`.
    if (ea.take == 0) ea.take = take;
    if (eb.take == 0) eb.take = take;
    fast_estimates.push_back(ea);
    naive_estimates.push_back(eb);
  }
  check.fast = compute_metrics(performance, fast_estimates, options.metrics);
  check.naive = compute_metrics(performance, naive_estimates, options.metrics);
  check.ran = true;
  return check;
}

}  // namespace

std::string_view tracker_kind_name(TrackerKind kind) {
  for (const KindName& k : kKindNames) {
    if (k.kind == kind) return k.name;
  }
  return "?";
}

bool parse_tracker_kind(std::string_view name, TrackerKind& kind) {
  for (const KindName& k : kKindNames) {
    if (k.name == name) {
      kind = k.kind;
      return true;
    }
  }
  return false;
}

std::vector<TrackerKind> all_tracker_kinds() {
  std::vector<TrackerKind> kinds;
  for (const KindName& k : kKindNames) kinds.push_back(k.kind);
  return kinds;
}

namespace {

// The jump HMM, in beam mode when EvalOptions::beam asks for it.
Result<std::unique_ptr<Tracker>> hmm_tracker(const TemplateModel& model, const FollowParams& params,
                                             const EvalOptions& options,
                                             std::shared_ptr<const JumpCandidateIndex> index) {
  if (options.beam && index) {
    return boxed(BeamFollower::create(model, params, BeamParams::suited_to(params), std::move(index)));
  }
  if (options.beam) {
    return boxed(BeamFollower::create(model, params, BeamParams::suited_to(params)));
  }
  return boxed(HmmFollower::create(model, params));
}

}  // namespace

Result<std::unique_ptr<Tracker>> make_eval_tracker(TrackerKind kind, const TemplateModel& model,
                                                   const EvalOptions& options,
                                                   std::shared_ptr<const JumpCandidateIndex> index) {
  switch (kind) {
    case TrackerKind::kHmm:
      return hmm_tracker(model, options.hmm, options, std::move(index));
    case TrackerKind::kHmmPaper: {
      // The paper's transitions [4.2]; the emission and decision settings are ours.
      FollowParams params = FollowParams::paper();
      params.emission_sigma = options.hmm.emission_sigma;
      params.pause_distance_per_dim = options.hmm.pause_distance_per_dim;
      params.lost_distance_per_dim = options.hmm.lost_distance_per_dim;
      params.sensor_noise_time_constant_s = options.hmm.sensor_noise_time_constant_s;
      params.pause_noise_factor = options.hmm.pause_noise_factor;
      params.emission_noise_factor = options.hmm.emission_noise_factor;
      params.emission_noise_allowance = options.hmm.emission_noise_allowance;
      params.noise_filter_density = options.hmm.noise_filter_density;
      params.noise_filter_allowance = options.hmm.noise_filter_allowance;
      params.pause_noise_allowance = options.hmm.pause_noise_allowance;
      params.lost_residual_per_dim = options.hmm.lost_residual_per_dim;
      params.lost_noise_factor = options.hmm.lost_noise_factor;
      params.lost_residual_factor = options.hmm.lost_residual_factor;
      params.lost_confirm_s = options.hmm.lost_confirm_s;
      params.found_confirm_per_lost_s = options.hmm.found_confirm_per_lost_s;
      params.found_confirm_max_s = options.hmm.found_confirm_max_s;
      params.pause_reported_lost = options.hmm.pause_reported_lost;
      params.held_place_lost_s = options.hmm.held_place_lost_s;
      params.held_place_reach_s = options.hmm.held_place_reach_s;
      params.found_still_spell_s = options.hmm.found_still_spell_s;
      params.found_still_reach_s = options.hmm.found_still_reach_s;
      params.missing_lost_s = options.hmm.missing_lost_s;
      params.confidence_window_frames = options.hmm.confidence_window_frames;
      params.max_steps_per_frame = options.hmm.max_steps_per_frame;
      return hmm_tracker(model, params, options, std::move(index));
    }
    case TrackerKind::kLeftToRight: {
      FollowParams params = options.hmm;
      params.jump_enabled = false;
      params.resume_weights.clear();
      return boxed(HmmFollower::create(model, params));  // no beam mode without the pause state
    }
    case TrackerKind::kNearestNeighbour:
      return boxed(NearestNeighbourTracker::create(model, options.hmm));
    case TrackerKind::kOnlineDtw: {
      OnlineDtwParams params = options.dtw;
      params.emission_sigma = options.hmm.emission_sigma;
      params.lost_distance_per_dim = options.hmm.lost_distance_per_dim;
      params.confidence_window_frames = options.hmm.confidence_window_frames;
      params.max_steps_per_frame = options.hmm.max_steps_per_frame;
      return boxed(OnlineDtwTracker::create(model, params));
    }
    case TrackerKind::kNaiveHmm:
      return boxed(NaiveHmmFollower::create(model, options.hmm));
  }
  return Error{"unknown tracker"};
}

Result<std::vector<FrameEstimate>> follow_performance(const DuetLibrary& library,
                                                      const Performance& performance,
                                                      std::unique_ptr<Tracker> tracker,
                                                      const PostureBiasParams& bias) {
  Result<FollowSession> created = FollowSession::create(
      library, performance.motion.skeleton_ptr(), performance.roles, std::move(tracker), bias);
  if (!created) return created.error();
  FollowSession& session = created.value();
  if (Status s = session.set_head_height(performance.told_head_height_m); !s) return s.error();
  if (Status s = session.set_arms_forward(performance.told_arms_forward); !s) return s.error();
  std::vector<FrameEstimate> estimates;
  estimates.reserve(static_cast<std::size_t>(performance.frame_count()));
  for (int f = 0; f < performance.frame_count(); ++f) {
    const Timed t = timed([&] {
      return session.step(performance.motion.translations_ls(f), performance.motion.rotations_ls(f),
                          performance.times_s[static_cast<std::size_t>(f)]);
    });
    estimates.push_back(to_estimate(t.result, t.us));
  }
  return estimates;
}

Result<EvalReport> run_evaluation(const DuetLibrary& library, const DuetLibrary* partner_library,
                                  const EvalOptions& options, const EvalProgress& progress) {
  const int take_count = static_cast<int>(library.takes().size());
  for (const int take : options.takes) {
    if (take < 0 || take >= take_count) {
      return Error{"take " + std::to_string(take) + " does not exist: the library has " +
                   std::to_string(take_count) + " takes (0.." + std::to_string(take_count - 1) +
                   ")"};
    }
  }
  if (options.takes.empty()) return Error{"no take to perform from"};
  if (options.cases.empty()) return Error{"no case to run"};
  for (const EvalCase& c : options.cases) {
    if (!c.partner_role) continue;
    if (partner_library == nullptr) {
      return Error{"case " + c.name + " needs a library built with role=partner"};
    }
    if (static_cast<int>(partner_library->takes().size()) != take_count) {
      return Error{"the partner-role library holds another set of takes"};
    }
  }

  std::vector<TrackerKind> trackers;
  bool naive = false;
  for (const TrackerKind kind : options.trackers) {
    if (kind == TrackerKind::kNaiveHmm) {
      naive = true;
    } else {
      trackers.push_back(kind);
    }
  }

  EvalReport report;
  report.library_states = library.model().num_states();
  report.partner_options = options.partner;
  for (const DuetTake& t : library.takes()) report.take_names.push_back(t.name);

  // A recorded case is performed once, from its own take; every other case from each take.
  const auto takes_of = [&](const EvalCase& eval_case) {
    return eval_case.recipe.recorded && !eval_case.recipe.recorded->truth.empty()
               ? std::vector<int>{eval_case.recipe.recorded->truth.front().take}
               : options.takes;
  };
  long long total = naive ? 1 : 0;
  for (const EvalCase& eval_case : options.cases) {
    total += static_cast<long long>(takes_of(eval_case).size() *
                                    (trackers.size() + (options.partner_metrics ? 1 : 0)));
  }
  long long done = 0;

  // Which misses show the user what the truth shows (Metrics::within_100ms_alike), per library.
  Result<LookAlikeFrames> look_alikes = LookAlikeFrames::build(library);
  if (!look_alikes) return look_alikes.error();
  std::optional<LookAlikeFrames> partner_look_alikes;
  if (std::ranges::any_of(options.cases, [](const EvalCase& c) { return c.partner_role; })) {
    Result<LookAlikeFrames> built = LookAlikeFrames::build(*partner_library);
    if (!built) return built.error();
    partner_look_alikes = std::move(built).value();
  }

  for (const EvalCase& eval_case : options.cases) {
    const DuetLibrary& lib = eval_case.partner_role ? *partner_library : library;
    const LookAlikeFrames& lib_look_alikes =
        eval_case.partner_role ? *partner_look_alikes : look_alikes.value();
    std::vector<MetricsAccumulator> pooled(trackers.size(), MetricsAccumulator(options.metrics));
    std::vector<std::vector<std::pair<int, Metrics>>> per_take(trackers.size());
    std::vector<std::vector<ScoredFrame>> kept(trackers.size());
    const std::size_t configs = options.partner_metrics ? options.partner_configs.size() : 0;
    std::vector<PartnerMetricsAccumulator> partner_pooled(
        configs, PartnerMetricsAccumulator(options.partner));
    std::vector<std::vector<std::pair<int, PartnerMetrics>>> partner_per_take(configs);
    double loop_us_sum = 0.0;
    long long loop_frames = 0;
    const std::vector<int> case_takes = takes_of(eval_case);
    for (std::size_t ti = 0; ti < case_takes.size(); ++ti) {
      const int take = case_takes[ti];
      if (take < 0 || take >= static_cast<int>(lib.takes().size())) {
        return Error{"case " + eval_case.name + ": take " + std::to_string(take) +
                     " is not in the library"};
      }
      const std::vector<SourceTake> sources = sources_for(lib, take, eval_case.across_takes);
      Result<Performance> made = make_performance(
          sources, eval_case.recipe,
          derive_seed(options.seed, name_hash(eval_case.seed_key()), static_cast<std::uint64_t>(take)));
      if (!made) return Error{"case " + eval_case.name + ": " + made.error().message};
      const Performance& performance = made.value();
      for (std::size_t k = 0; k < trackers.size(); ++k) {
        const std::string label = eval_case.name + " / " +
                                  lib.takes()[static_cast<std::size_t>(take)].name + " / " +
                                  std::string(tracker_kind_name(trackers[k]));
        if (progress) progress(done, total, label);
        Result<std::unique_ptr<Tracker>> tracker =
            make_eval_tracker(trackers[k], lib.model(), options, lib.candidate_index());
        if (!tracker) return Error{label + ": " + tracker.error().message};
        PostureBiasParams bias;
        bias.lost_confidence = options.lost_confidence;
        Result<std::vector<FrameEstimate>> estimates =
            follow_performance(lib, performance, std::move(tracker).value(), bias);
        if (!estimates) return Error{label + ": " + estimates.error().message};
        MetricsAccumulator one(options.metrics);
        one.add(performance, estimates.value(), &lib_look_alikes);
        if (options.keep_frames) {
          for (std::size_t f = 0; f < estimates.value().size(); ++f) {
            const TruthFrame& truth = performance.truth[f];
            if (truth.in_pause) continue;
            kept[k].push_back({take,
                               frame_error_ms(truth, estimates.value()[f],
                                              performance.template_rate_hz, options.metrics),
                               estimates.value()[f], truth});
          }
        }
        per_take[k].emplace_back(take, one.summary());
        pooled[k].merge(one);
        if (eval_case.name == options.trace_case && ti == 0) {
          report.traces.push_back({eval_case.name, std::string(tracker_kind_name(trackers[k])),
                                   take, performance.template_rate_hz, performance.times_s,
                                   performance.truth, std::move(estimates).value()});
        }
        ++done;
      }
      if (configs > 0) {
        // The synthesized partner, with the "hmm" tracker as `duet follow` runs it.
        const std::string label = eval_case.name + " / " +
                                  lib.takes()[static_cast<std::size_t>(take)].name + " / partner";
        if (progress) progress(done, total, label);
        Result<std::unique_ptr<Tracker>> tracker =
            make_eval_tracker(TrackerKind::kHmm, lib.model(), options, lib.candidate_index());
        if (!tracker) return Error{label + ": " + tracker.error().message};
        Result<PartnerPerformanceResult> partner = run_partner_performance(
            lib, performance, std::move(tracker).value(), options.partner_configs, options.partner);
        if (!partner) return Error{label + ": " + partner.error().message};
        for (std::size_t c = 0; c < configs; ++c) {
          const PartnerMetricsAccumulator& one = partner.value().configs[c];
          partner_per_take[c].emplace_back(take, one.summary());
          partner_pooled[c].merge(one);
        }
        loop_us_sum += partner.value().loop_step_us * performance.frame_count();
        loop_frames += performance.frame_count();
        ++done;
      }
    }
    for (std::size_t k = 0; k < trackers.size(); ++k) {
      report.rows.push_back({eval_case.name, std::string(tracker_kind_name(trackers[k])),
                             pooled[k].summary(), std::move(per_take[k]), std::move(kept[k])});
    }
    for (std::size_t c = 0; c < configs; ++c) {
      const PartnerConfig& config = options.partner_configs[c];
      report.partner_rows.push_back(
          {eval_case.name, config.name, config.params.align, partner_pooled[c].summary(),
           std::move(partner_per_take[c]),
           loop_frames > 0 ? loop_us_sum / static_cast<double>(loop_frames) : 0.0});
    }
  }

  if (naive) {
    // On naive_case if it performs in the user's role from one take, else on the first case that
    // does.
    const auto eligible = [](const EvalCase& c) {
      return !c.partner_role && !c.across_takes && !c.recipe.recorded;
    };
    const EvalCase* chosen = nullptr;
    for (const EvalCase& c : options.cases) {
      if (c.name == options.naive_case && eligible(c)) chosen = &c;
    }
    for (const EvalCase& c : options.cases) {
      if (chosen == nullptr && eligible(c)) chosen = &c;
    }
    if (chosen != nullptr) {
      if (progress) progress(done, total, "naive-hmm on one take");
      Result<NaiveCheck> check = run_naive_check(library, *chosen, options.takes[0], options);
      if (!check) return Error{"naive-hmm: " + check.error().message};
      report.naive = std::move(check).value();
    }
    ++done;
  }
  if (progress) progress(done, total, "done");
  return report;
}

}  // namespace duet
