#include "duet/eval/performance.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <random>

#include "duet/math/rotation.h"
#include "duet/motion/arms_forward.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/limits.h"
#include "duet/motion/retarget.h"
#include "duet/motion/up_axis.h"
#include "duet/partner/alignment.h"

namespace duet {

std::uint64_t derive_seed(std::uint64_t base, std::uint64_t a, std::uint64_t b) {
  // splitmix64 over a mix of the three, so neighbouring indices give unrelated streams.
  std::uint64_t z = base ^ (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xC2B2AE3D27D4EB4Full);
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

// A rigid move of the whole body about the vertical axis: turn by yaw about the world origin,
// then translate. Applied to the skeleton root (joint 0), whose local transform is its world one.
struct Placement {
  double yaw = 0.0;
  Vec3 offset = Vec3::Zero();

  void apply(Vec3& root_position, Quat& root_rotation) const {
    const Quat turn = yaw_rotation(yaw);
    root_position = turn * root_position + offset;
    root_rotation = turn * root_rotation;
  }
};

// The placement that puts a raw root (position, heading) at a target root: same heading, same
// horizontal position. The height stays the take's own (it belongs to the pose).
Placement align_root(const Vec3& target_position, double target_yaw, const Vec3& raw_position,
                     double raw_yaw) {
  Placement p;
  p.yaw = wrap_angle(target_yaw - raw_yaw);
  p.offset = target_position - yaw_rotation(p.yaw) * raw_position;
  p.offset.y() = 0.0;
  return p;
}

struct RootSample {
  Vec3 position;
  double yaw;
};

RootSample root_at(const Clip& clip, double tau_s, const Placement& placement, Pose& scratch) {
  clip.sample(tau_s, scratch);
  Vec3 position = scratch.translations_ls[0];
  Quat rotation = scratch.rotations_ls[0];
  placement.apply(position, rotation);
  return {position, heading_yaw(rotation)};
}

class TempoCurve {
 public:
  TempoCurve(const TempoOptions& options, std::uint64_t seed) : options_(options) {
    Rng rng(seed);
    phase_ = uniform(rng, 0.0, 2.0 * kPi);
  }
  double factor(double t_s) const {
    if (!options_.drifting()) return options_.factor;
    const double mid = 0.5 * (options_.drift_low + options_.drift_high);
    const double amplitude = 0.5 * (options_.drift_high - options_.drift_low);
    return mid + amplitude * std::sin(2.0 * kPi * t_s / options_.drift_period_s + phase_);
  }
  double fastest() const { return options_.drifting() ? options_.drift_high : options_.factor; }

 private:
  TempoOptions options_;
  double phase_ = 0.0;
};

// One piece of a performance: template time [begin_s, end_s] of a source. jump: the piece does
// not continue the previous one (it is the same source with begin_s == previous end_s otherwise).
struct ScriptEntry {
  int source = 0;
  double begin_s = 0.0;
  double end_s = 0.0;
  double pause_before_s = 0.0;  // a hold before a jump
  bool jump = false;
};

struct SwayOptions {
  double sway_m = 0.0;
  double sway_deg = 0.0;
};

// Plays a script at a tempo and sensor rate. duration_s <= 0 plays to the script's end.
Performance perform_script(std::span<const SourceTake> sources,
                           const std::vector<ScriptEntry>& script, const TempoCurve& tempo,
                           double rate_hz, double duration_s, const SwayOptions& sway) {
  assert(!sources.empty() && !script.empty());
  const Clip& first_clip = *sources[0].clip;
  const double template_fps = first_clip.frame_rate();
  const double rate = rate_hz > 0.0 ? rate_hz : template_fps;
  const double dt = 1.0 / rate;
  const int joints = first_clip.joint_count();
  const int spine = sources[0].roles[Role::kSpine];

  std::vector<Vec3> translations;
  std::vector<Quat> rotations;
  Performance out;
  out.roles = sources[0].roles;
  out.template_rate_hz = template_fps;

  std::size_t e = 0;
  double tau = script[0].begin_s;
  Placement place;  // the first piece stays where the take has it
  bool pausing = false;
  double pause_length = 0.0, pause_elapsed = 0.0, hold_tau = 0.0;
  int hold_source = 0;
  bool pending_jump = false;
  Pose pose, scratch;

  for (long long k = 0;; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (duration_s > 0.0 && t >= duration_s - 1e-9) break;
    TruthFrame truth;
    if (pausing) {
      const SourceTake& source = sources[static_cast<std::size_t>(hold_source)];
      source.clip->sample(hold_tau, pose);
      place.apply(pose.translations_ls[0], pose.rotations_ls[0]);
      // A tiny sway that fades in and out, so the hold starts and ends on the held pose.
      const double envelope = std::sin(kPi * std::clamp(pause_elapsed / pause_length, 0.0, 1.0));
      const double s = pause_elapsed;
      pose.translations_ls[0] +=
          envelope * sway.sway_m *
          Vec3(std::sin(2.0 * kPi * 0.9 * s), 0.0, std::sin(2.0 * kPi * 0.6 * s + 1.0));
      if (spine > 0 && spine < joints) {
        const Vec3 v = envelope * deg_to_rad(sway.sway_deg) *
                       Vec3(std::sin(2.0 * kPi * 0.7 * s), 0.5 * std::sin(2.0 * kPi * 1.1 * s),
                            std::sin(2.0 * kPi * 0.5 * s + 2.0));
        const auto j = static_cast<std::size_t>(spine);
        pose.rotations_ls[j] = (pose.rotations_ls[j] * exp_map(v)).normalized();
      }
      truth = {source.take, hold_tau * template_fps, true, false};
    } else {
      const SourceTake& source = sources[static_cast<std::size_t>(script[e].source)];
      source.clip->sample(tau, pose);
      place.apply(pose.translations_ls[0], pose.rotations_ls[0]);
      truth = {source.take, tau * template_fps, false, pending_jump};
      pending_jump = false;
    }
    translations.insert(translations.end(), pose.translations_ls.begin(),
                        pose.translations_ls.end());
    rotations.insert(rotations.end(), pose.rotations_ls.begin(), pose.rotations_ls.end());
    out.truth.push_back(truth);
    out.times_s.push_back(t);

    // Advance to the next input frame.
    if (pausing) {
      pause_elapsed += dt;
      if (pause_elapsed >= pause_length - 1e-9) {
        pausing = false;
        const ScriptEntry& next = script[e];
        tau = next.begin_s;
        // The new piece starts where the dancer stands and faces after the hold.
        const RootSample held =
            root_at(*sources[static_cast<std::size_t>(hold_source)].clip, hold_tau, place, scratch);
        const RootSample raw =
            root_at(*sources[static_cast<std::size_t>(next.source)].clip, tau, {}, scratch);
        place = align_root(held.position, held.yaw, raw.position, raw.yaw);
        pending_jump = true;
      }
      continue;
    }
    tau += tempo.factor(t + 0.5 * dt) * dt;
    bool finished = false;
    while (tau > script[e].end_s + 1e-9) {
      const double overflow = tau - script[e].end_s;
      if (e + 1 == script.size()) {
        finished = true;
        break;
      }
      const ScriptEntry& previous = script[e];
      const ScriptEntry& next = script[++e];
      if (!next.jump) {  // the take goes on: same placement
        tau = next.begin_s + overflow;
        continue;
      }
      if (next.pause_before_s > 0.0) {
        pausing = true;
        pause_length = next.pause_before_s;
        pause_elapsed = 0.0;
        hold_source = previous.source;
        hold_tau = previous.end_s;
        break;
      }
      // A jump in stride: the new piece continues the root path where the old one was going.
      const RootSample target = root_at(*sources[static_cast<std::size_t>(previous.source)].clip,
                                        previous.end_s + overflow, place, scratch);
      tau = next.begin_s + overflow;
      const RootSample raw =
          root_at(*sources[static_cast<std::size_t>(next.source)].clip, tau, {}, scratch);
      place = align_root(target.position, target.yaw, raw.position, raw.yaw);
      pending_jump = true;
    }
    if (finished) break;
  }

  const int frames = static_cast<int>(out.truth.size());
  out.motion = Clip(first_clip.skeleton_ptr(), rate, frames);
  for (int f = 0; f < frames; ++f) {
    const auto begin = static_cast<std::ptrdiff_t>(f) * joints;
    std::copy(translations.begin() + begin, translations.begin() + begin + joints,
              out.motion.translations_ls(f).begin());
    std::copy(rotations.begin() + begin, rotations.begin() + begin + joints,
              out.motion.rotations_ls(f).begin());
  }
  return out;
}

double last_time(const Clip& clip) { return (clip.frame_count() - 1) / clip.frame_rate(); }

// At most how many frames the recipe makes from `take`: the duration (improvise: the given one,
// else the take's; play: the take at its slowest tempo) times the sensor rate.
double frames_bound(const Clip& take, const PerformanceRecipe& recipe) {
  const double rate_hz = recipe.improvise ? recipe.improvise_options.rate_hz : recipe.play.rate_hz;
  const double rate = rate_hz > 0.0 ? rate_hz : take.frame_rate();
  double seconds = 0.0;
  if (recipe.improvise) {
    const double duration = recipe.improvise_options.duration_s;
    seconds = duration > 0.0 ? duration : last_time(take);
  } else {
    const TempoOptions& tempo = recipe.play.tempo;
    seconds = last_time(take) / (tempo.drifting() ? tempo.drift_low : tempo.factor);
  }
  return std::ceil(seconds * rate) + 1.0;
}

}  // namespace

Performance play(const SourceTake& source, const PlayOptions& options) {
  assert(source.clip != nullptr && source.clip->frame_count() >= 2);
  const std::vector<ScriptEntry> script = {{0, 0.0, last_time(*source.clip), 0.0, false}};
  const TempoCurve tempo(options.tempo, derive_seed(options.seed, 1));
  return perform_script(std::span<const SourceTake>(&source, 1), script, tempo, options.rate_hz,
                        0.0, {});
}

Result<Performance> improvise(std::span<const SourceTake> sources,
                              const ImproviseOptions& options) {
  if (sources.empty()) return Error{"improvise: no take to perform from"};
  for (const SourceTake& s : sources) {
    if (s.clip == nullptr || s.clip->frame_count() < 2) {
      return Error{"improvise: take " + std::to_string(s.take) + " has fewer than 2 frames"};
    }
    if (s.clip->joint_count() != sources[0].clip->joint_count()) {
      return Error{"improvise: takes " + std::to_string(sources[0].take) + " and " +
                   std::to_string(s.take) + " have different skeletons"};
    }
    if (std::abs(s.clip->frame_rate() - sources[0].clip->frame_rate()) > 1e-9) {
      return Error{"improvise: takes " + std::to_string(sources[0].take) + " and " +
                   std::to_string(s.take) + " have different frame rates"};
    }
  }
  if (!(options.segment_min_s > 0.0 && options.segment_max_s >= options.segment_min_s)) {
    return Error{"improvise: need 0 < segment_min_s <= segment_max_s"};
  }
  if (!(options.pause_min_s >= 0.0 && options.pause_max_s >= options.pause_min_s)) {
    return Error{"improvise: need 0 <= pause_min_s <= pause_max_s"};
  }
  Rng rng(derive_seed(options.seed, 2));

  // Cut every source into consecutive segments.
  struct Segment {
    int source;
    double begin_s, end_s;
    int successor;  // index of the segment that continues this one, -1 at the end of a take
  };
  std::vector<Segment> segments;
  for (std::size_t s = 0; s < sources.size(); ++s) {
    const double end = last_time(*sources[s].clip);
    double begin = 0.0;
    while (begin < end - 1e-9) {
      double cut = begin + uniform(rng, options.segment_min_s, options.segment_max_s);
      if (end - cut < options.segment_min_s) cut = end;  // no stub at the end of the take
      segments.push_back({static_cast<int>(s), begin, cut, -1});
      if (cut < end) segments.back().successor = static_cast<int>(segments.size());
      begin = cut;
    }
  }

  // Replay them in another order until the performance is long enough.
  const TempoCurve tempo(options.tempo, derive_seed(options.seed, 1));
  const double duration =
      options.duration_s > 0.0 ? options.duration_s : last_time(*sources[0].clip);
  const auto count = static_cast<int>(segments.size());
  std::vector<ScriptEntry> script;
  int current = std::uniform_int_distribution<int>(0, count - 1)(rng);
  double planned_s = 0.0;
  for (;;) {
    const Segment& seg = segments[static_cast<std::size_t>(current)];
    ScriptEntry entry{seg.source, seg.begin_s, seg.end_s, 0.0, !script.empty()};
    if (!script.empty()) {
      const ScriptEntry& previous = script.back();
      entry.jump =
          !(previous.source == seg.source && std::abs(previous.end_s - seg.begin_s) < 1e-9);
      if (entry.jump && uniform(rng, 0.0, 1.0) < options.pause_prob) {
        entry.pause_before_s = uniform(rng, options.pause_min_s, options.pause_max_s);
      }
    }
    script.push_back(entry);
    // Lower bound of the performance time this piece takes (at the fastest tempo).
    planned_s += entry.pause_before_s + (seg.end_s - seg.begin_s) / tempo.fastest();
    if (planned_s > duration + 1.0) break;
    const int successor = seg.successor;
    if (successor >= 0 && uniform(rng, 0.0, 1.0) < options.continue_prob) {
      current = successor;
    } else if (count == 1) {
      current = 0;  // a jump back to its own start
    } else {
      // Any segment but the successor (that would be no jump): repeats and skips.
      do {
        current = std::uniform_int_distribution<int>(0, count - 1)(rng);
      } while (current == successor);
    }
  }
  return perform_script(sources, script, tempo, options.rate_hz, duration,
                        {options.sway_m, options.sway_deg});
}

namespace {

// Calls visit(world positions) for every frame of the performance's motion, in order.
template <typename Visit>
void for_each_world_pose(const Clip& motion, Visit&& visit) {
  const Skeleton& skeleton = motion.skeleton();
  const auto joints = static_cast<std::size_t>(skeleton.joint_count());
  std::vector<Vec3> positions(joints);
  std::vector<Quat> rotations(joints);
  for (int f = 0; f < motion.frame_count(); ++f) {
    forward_kinematics(skeleton, motion.translations_ls(f), motion.rotations_ls(f), positions,
                       rotations);
    visit(std::span<const Vec3>(positions));
  }
}

}  // namespace

void record_true_wrists(Performance& performance) {
  const int left = performance.roles[Role::kLeftWrist],
            right = performance.roles[Role::kRightWrist];
  performance.true_wrists_ws.clear();
  if (left < 0 || right < 0) return;
  performance.true_wrists_ws.reserve(static_cast<std::size_t>(performance.frame_count()));
  for_each_world_pose(performance.motion, [&](std::span<const Vec3> positions) {
    performance.true_wrists_ws.push_back(
        {positions[static_cast<std::size_t>(left)], positions[static_cast<std::size_t>(right)]});
  });
}

void record_true_headings(Performance& performance) {
  performance.true_headings_ws.clear();
  if (performance.roles[Role::kLeftHip] < 0 || performance.roles[Role::kRightHip] < 0) return;
  performance.true_headings_ws.reserve(static_cast<std::size_t>(performance.frame_count()));
  for_each_world_pose(performance.motion, [&](std::span<const Vec3> positions) {
    performance.true_headings_ws.push_back(body_heading_frame(positions, performance.roles));
  });
}

namespace {

// Spans of [min_s, max_s] seconds of the performance's time, one every every_s on average
// (exponential waits between them; never the first frame): per frame the index of the span it
// falls in, -1 outside. Empty when there are none.
std::vector<int> random_spans(const std::vector<double>& times_s, double every_s, double min_s,
                              double max_s, Rng& rng) {
  const int frames = static_cast<int>(times_s.size());
  if (!(every_s > 0.0) || frames == 0) return {};
  std::exponential_distribution<double> wait(1.0 / every_s);
  const double low = std::max(min_s, 0.0);
  const double high = std::max(max_s, low);
  std::vector<int> span_of(static_cast<std::size_t>(frames), -1);
  double start = times_s.front() + wait(rng);
  int f = 1;  // the first frame is never in a span
  for (int span = 0; start <= times_s.back(); ++span) {
    const double end = start + uniform(rng, low, high);
    for (; f < frames && times_s[static_cast<std::size_t>(f)] < end; ++f) {
      if (times_s[static_cast<std::size_t>(f)] >= start)
        span_of[static_cast<std::size_t>(f)] = span;
    }
    start = end + wait(rng);
  }
  return span_of;
}

// Calls begin(span) as each span of random_spans' spans begins, then at(frame) on each of its
// frames, in frame order (a span's random draws in begin keep their order in the stream).
template <typename Begin, typename At>
void for_each_span_frame(const std::vector<int>& spans, Begin&& begin, At&& at) {
  int current = -1;
  for (std::size_t f = 1; f < spans.size(); ++f) {
    const int span = spans[f];
    if (span < 0) continue;
    if (span != current) {
      current = span;
      begin(span);
    }
    at(static_cast<int>(f));
  }
}

// SensorNoiseOptions' occlusions: in each span one arm drawn at random keeps its shoulder's,
// elbow's and wrist's local rotations of the frame before the occlusion began, while the rest of
// the body moves on. Their own random stream; before the noise, which the sensor goes on adding.
void hold_occluded_arms(Performance& performance, const SensorNoiseOptions& options) {
  Rng rng(derive_seed(options.seed, 8));
  const std::vector<int> spans =
      random_spans(performance.times_s, options.occlusion_every_s, options.occlusion_min_s,
                   options.occlusion_max_s, rng);
  constexpr std::array<std::array<Role, 3>, 2> kArmJoints = {
      {{Role::kLeftShoulder, Role::kLeftElbow, Role::kLeftWrist},
       {Role::kRightShoulder, Role::kRightElbow, Role::kRightWrist}}};
  std::bernoulli_distribution right(0.5);
  std::size_t arm = 0;
  Clip& motion = performance.motion;
  for_each_span_frame(
      spans, [&](int) { arm = right(rng) ? 1 : 0; },
      [&](int frame) {
        for (const Role role : kArmJoints[arm]) {
          const int joint = performance.roles[role];
          if (joint < 0) continue;
          const auto i = static_cast<std::size_t>(joint);
          motion.rotations_ls(frame)[i] = motion.rotations_ls(frame - 1)[i];
        }
      });
}

// A random direction, uniform on the sphere.
Vec3 random_direction(Rng& rng) {
  std::normal_distribution<double> component(0.0, 1.0);
  for (;;) {
    const Vec3 v(component(rng), component(rng), component(rng));
    if (v.norm() > 1e-9) return v.normalized();
  }
}

// SensorNoiseOptions' glitches: in each span one joint of the trunk, arms or legs (drawn at
// random among the roles the rig has) turned by one random rotation. Before the noise.
void turn_glitched_joints(Performance& performance, const SensorNoiseOptions& options) {
  Rng rng(derive_seed(options.seed, 15));
  const std::vector<int> spans = random_spans(performance.times_s, options.glitch_every_s,
                                              options.glitch_min_s, options.glitch_max_s, rng);
  if (spans.empty()) return;
  constexpr std::array kGlitchRoles = {
      Role::kSpine,        Role::kChest,      Role::kNeck,      Role::kHead,
      Role::kLeftShoulder, Role::kLeftElbow,  Role::kLeftWrist, Role::kRightShoulder,
      Role::kRightElbow,   Role::kRightWrist, Role::kLeftHip,   Role::kLeftKnee,
      Role::kLeftAnkle,    Role::kRightHip,   Role::kRightKnee, Role::kRightAnkle};
  std::vector<int> joints;
  for (const Role role : kGlitchRoles) {
    if (performance.roles[role] >= 0) joints.push_back(performance.roles[role]);
  }
  if (joints.empty()) return;
  std::uniform_int_distribution<std::size_t> pick(0, joints.size() - 1);
  std::size_t joint = 0;
  Quat turn = Quat::Identity();
  Clip& motion = performance.motion;
  for_each_span_frame(
      spans,
      [&](int) {
        joint = static_cast<std::size_t>(joints[pick(rng)]);
        const double angle = deg_to_rad(uniform(
            rng, options.glitch_min_deg, std::max(options.glitch_min_deg, options.glitch_max_deg)));
        turn = Quat(Eigen::AngleAxisd(angle, random_direction(rng)));
      },
      [&](int f) {
        motion.rotations_ls(f)[joint] = (motion.rotations_ls(f)[joint] * turn).normalized();
      });
}

// SensorNoiseOptions' slow errors: per joint a constant offset plus a drifting one, as rotation
// vectors, advanced frame by frame with the performance's timestamps.
class SlowRotationErrors {
 public:
  SlowRotationErrors(const SensorNoiseOptions& options, int joints)
      : rng_(derive_seed(options.seed, 7)),
        drift_sigma_(deg_to_rad(options.drift_deg) / std::sqrt(3.0)),
        drift_time_s_(std::max(options.drift_time_s, 1e-3)),
        bias_(static_cast<std::size_t>(joints), Vec3::Zero()),
        drift_(static_cast<std::size_t>(joints), Vec3::Zero()) {
    std::normal_distribution<double> bias(0.0, deg_to_rad(options.bias_deg) / std::sqrt(3.0));
    std::normal_distribution<double> drift(0.0, drift_sigma_);
    for (std::size_t j = 0; j < bias_.size(); ++j) {
      if (options.bias_deg > 0.0) bias_[j] = Vec3(bias(rng_), bias(rng_), bias(rng_));
      // Start from the stationary distribution: the drift is already there at the first frame.
      if (drift_sigma_ > 0.0) drift_[j] = Vec3(drift(rng_), drift(rng_), drift(rng_));
    }
    active_ = options.bias_deg > 0.0 || drift_sigma_ > 0.0;
  }

  bool active() const { return active_; }

  // Moves the drift on by dt seconds (exact discretisation of the Ornstein-Uhlenbeck process).
  void advance(double dt_s) {
    if (!(drift_sigma_ > 0.0) || !(dt_s > 0.0)) return;
    const double keep = std::exp(-dt_s / drift_time_s_);
    std::normal_distribution<double> step(0.0, drift_sigma_ * std::sqrt(1.0 - keep * keep));
    for (Vec3& d : drift_) d = keep * d + Vec3(step(rng_), step(rng_), step(rng_));
  }

  Vec3 error(std::size_t joint) const { return bias_[joint] + drift_[joint]; }

 private:
  Rng rng_;
  double drift_sigma_;
  double drift_time_s_;
  std::vector<Vec3> bias_;
  std::vector<Vec3> drift_;
  bool active_ = false;
};

}  // namespace

Performance with_sensor_noise(Performance performance, const SensorNoiseOptions& options) {
  Rng rng(derive_seed(options.seed, 3));
  // RMS angle of a rotation vector with three N(0, s^2) components is s * sqrt(3).
  std::normal_distribution<double> angle(0.0, deg_to_rad(options.rotation_deg) / std::sqrt(3.0));
  std::normal_distribution<double> position(0.0, options.position_m);
  Clip& motion = performance.motion;
  const Skeleton& skeleton = motion.skeleton();
  SlowRotationErrors slow(options, skeleton.joint_count());
  hold_occluded_arms(performance, options);
  turn_glitched_joints(performance, options);
  for (int f = 0; f < motion.frame_count(); ++f) {
    auto translations = motion.translations_ls(f);
    auto rotations = motion.rotations_ls(f);
    if (f > 0 && static_cast<std::size_t>(f) < performance.times_s.size()) {
      const auto k = static_cast<std::size_t>(f);
      slow.advance(performance.times_s[k] - performance.times_s[k - 1]);
    }
    for (int j = 0; j < skeleton.joint_count(); ++j) {
      const Joint& joint = skeleton.joints[static_cast<std::size_t>(j)];
      if (joint.end_site) continue;
      const auto i = static_cast<std::size_t>(j);
      if (slow.active()) rotations[i] = (rotations[i] * exp_map(slow.error(i))).normalized();
      if (options.rotation_deg > 0.0) {
        const Vec3 v(angle(rng), angle(rng), angle(rng));
        rotations[i] = (rotations[i] * exp_map(v)).normalized();
      }
      // The root's position only: a rig that animates every joint's offset (the Bandai rig)
      // carries its bone lengths there, which no sensor shakes.
      if (options.position_m > 0.0 && j == 0 && joint.has_position_channels()) {
        translations[i] += Vec3(position(rng), position(rng), position(rng));
      }
    }
  }
  return performance;
}

namespace {

// PointNoiseOptions' stalls: each span holds one controller's last pose, left and right in turn.
// Their own random stream, so performances without them stay what they were.
void hold_stalled_controllers(Performance& performance, const PointNoiseOptions& options) {
  Rng rng(derive_seed(options.seed, 9));
  const std::vector<int> spans = random_spans(performance.times_s, options.stall_every_s,
                                              options.stall_min_s, options.stall_max_s, rng);
  std::size_t hand = kPointsLeftHand;
  Clip& motion = performance.motion;
  for_each_span_frame(
      spans,
      [&](int span) {
        hand = static_cast<std::size_t>(span % 2 == 0 ? kPointsLeftHand : kPointsRightHand);
      },
      [&](int f) {
        motion.translations_ls(f)[hand] = motion.translations_ls(f - 1)[hand];
        motion.rotations_ls(f)[hand] = motion.rotations_ls(f - 1)[hand];
      });
}

// PointNoiseOptions' glitches: in each span one controller drawn at random reported a random
// distance away in one random direction. Their own random stream.
void displace_glitched_controllers(Performance& performance, const PointNoiseOptions& options) {
  Rng rng(derive_seed(options.seed, 16));
  const std::vector<int> spans = random_spans(performance.times_s, options.glitch_every_s,
                                              options.glitch_min_s, options.glitch_max_s, rng);
  std::bernoulli_distribution right(0.5);
  std::size_t hand = kPointsLeftHand;
  Vec3 offset = Vec3::Zero();
  Clip& motion = performance.motion;
  for_each_span_frame(
      spans,
      [&](int) {
        hand = static_cast<std::size_t>(right(rng) ? kPointsRightHand : kPointsLeftHand);
        offset = uniform(rng, options.glitch_min_m,
                         std::max(options.glitch_min_m, options.glitch_max_m)) *
                 random_direction(rng);
      },
      [&](int f) { motion.translations_ls(f)[hand] += offset; });
}

}  // namespace

Result<Performance> with_head_hands(Performance performance, const PointNoiseOptions& noise) {
  Result<Clip> points = head_hands_clip(performance.motion, performance.roles, noise.offsets);
  if (!points) return points.error();
  performance.motion = std::move(points).value();
  performance.roles = head_hands_roles();
  Rng rng(derive_seed(noise.seed, 5));
  std::normal_distribution<double> angle(0.0, deg_to_rad(noise.rotation_deg) / std::sqrt(3.0));
  std::normal_distribution<double> position(0.0, noise.position_m);
  Clip& motion = performance.motion;
  for (int f = 0; f < motion.frame_count(); ++f) {
    for (int j = kPointsHead; j <= kPointsRightHand; ++j) {
      const auto i = static_cast<std::size_t>(j);
      if (noise.position_m > 0.0) {
        motion.translations_ls(f)[i] += Vec3(position(rng), position(rng), position(rng));
      }
      if (noise.rotation_deg > 0.0) {
        const Vec3 v(angle(rng), angle(rng), angle(rng));
        motion.rotations_ls(f)[i] = (motion.rotations_ls(f)[i] * exp_map(v)).normalized();
      }
    }
  }
  displace_glitched_controllers(performance, noise);
  hold_stalled_controllers(performance, noise);
  if (noise.taken_out.any()) device_points_to_joints(noise.taken_out, motion);
  return performance;
}

namespace {

// Which frames fall into spans one every every_s on average, [min_s, max_s] long; empty when
// there are none. Each kind of span has its own random stream (stream), so performances without
// it stay what they were.
std::vector<bool> in_spans(const Performance& performance, const FrameLossOptions& options,
                           std::uint64_t stream, double every_s, double min_s, double max_s) {
  Rng rng(derive_seed(options.seed, stream));
  const std::vector<int> spans = random_spans(performance.times_s, every_s, min_s, max_s, rng);
  std::vector<bool> in(spans.size(), false);
  for (std::size_t f = 0; f < spans.size(); ++f) in[f] = spans[f] >= 0;
  return in;
}

}  // namespace

Performance with_frame_loss(Performance performance, const FrameLossOptions& options) {
  Rng rng(derive_seed(options.seed, 4));
  const int frames = performance.frame_count();
  const double period = 1.0 / performance.motion.frame_rate();
  const std::vector<bool> lost =
      in_spans(performance, options, 5, options.gap_every_s, options.gap_min_s, options.gap_max_s);
  const std::vector<bool> frozen = in_spans(performance, options, 6, options.freeze_every_s,
                                            options.freeze_min_s, options.freeze_max_s);
  // Bursts of 1..3 frames (mean 2): a burst starts after a kept frame with probability p, so the
  // dropped fraction is 2p / (1 + 2p).
  const double f = std::clamp(options.drop_fraction, 0.0, 0.9);
  const double burst_start = f / (2.0 * (1.0 - f));
  std::vector<int> kept;
  int dropping = 0;
  for (int k = 0; k < frames; ++k) {
    if (!lost.empty() && lost[static_cast<std::size_t>(k)]) continue;
    if (k > 0 && dropping > 0) {
      --dropping;
      continue;
    }
    kept.push_back(k);
    if (uniform(rng, 0.0, 1.0) < burst_start) {
      dropping = std::uniform_int_distribution<int>(1, 3)(rng);
    }
  }

  Performance out;
  out.roles = performance.roles;
  out.template_rate_hz = performance.template_rate_hz;
  out.told_head_height_m = performance.told_head_height_m;
  out.told_arms_forward = performance.told_arms_forward;
  const Clip& motion = performance.motion;
  out.motion = Clip(motion.skeleton_ptr(), motion.frame_rate(), static_cast<int>(kept.size()));
  bool carry_jump = false;
  double previous_time = -1e300;
  std::size_t next_kept = 0;
  for (int k = 0; k < frames; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (next_kept >= kept.size() || kept[next_kept] != k) {
      carry_jump = carry_jump || performance.truth[ks].jump;
      continue;
    }
    const int o = static_cast<int>(next_kept++);
    // A repeated frame is the sensor sending its last frame again; the real wrists moved on.
    if (!performance.true_wrists_ws.empty())
      out.true_wrists_ws.push_back(performance.true_wrists_ws[ks]);
    if (!performance.true_headings_ws.empty())
      out.true_headings_ws.push_back(performance.true_headings_ws[ks]);
    // Drawn only when asked for: performances without repeats stay what they were.
    const bool repeat =
        options.repeat_fraction > 0.0 && o > 0 && uniform(rng, 0.0, 1.0) < options.repeat_fraction;
    // A stall: the sensor holds its last pose while the dancer dances on (the truth moves on).
    const bool stalled = o > 0 && !frozen.empty() && frozen[ks];
    const bool held = stalled || repeat;
    std::ranges::copy(held ? out.motion.translations_ls(o - 1) : motion.translations_ls(k),
                      out.motion.translations_ls(o).begin());
    std::ranges::copy(held ? out.motion.rotations_ls(o - 1) : motion.rotations_ls(k),
                      out.motion.rotations_ls(o).begin());
    if (repeat && !stalled) {
      TruthFrame truth = out.truth.back();
      carry_jump = carry_jump || performance.truth[ks].jump;
      truth.jump = false;
      out.truth.push_back(truth);
    } else {
      TruthFrame truth = performance.truth[ks];
      truth.jump = truth.jump || carry_jump;
      carry_jump = false;
      out.truth.push_back(truth);
    }
    double time = performance.times_s[ks];
    if (options.jitter_s > 0.0) time += uniform(rng, 0.0, options.jitter_s);
    if (uniform(rng, 0.0, 1.0) < options.late_fraction) {
      time += uniform(rng, 0.0, options.late_max_frames) * period;
    }
    // Frames arrive in order: a frame after a late one cannot carry an earlier timestamp.
    time = std::max(time, previous_time + 1e-4);
    out.times_s.push_back(time);
    previous_time = time;
  }
  return out;
}

Performance with_body_scale(Performance performance, double factor) {
  performance.motion.scale_lengths(factor);
  return performance;
}

Performance with_room_placement(Performance performance, double yaw_rad, const Vec3& offset_m) {
  const Placement placement{yaw_rad, offset_m};
  Clip& motion = performance.motion;
  for (int f = 0; f < motion.frame_count(); ++f) {
    placement.apply(motion.translations_ls(f)[0], motion.rotations_ls(f)[0]);
  }
  return performance;
}

Performance with_world_tilt(Performance performance, double tilt_deg) {
  turn_world(performance.motion, Quat(Eigen::AngleAxisd(deg_to_rad(tilt_deg), Vec3::UnitX())));
  return performance;
}

Quat level_as_loaded(Performance& performance) {
  const UpAxisDetection detection = detect_up_axis(performance.motion, performance.roles);
  if (detection.axis != UpAxis::kPosY) return Quat::Identity();
  const Quat level = levelling_rotation(detection);
  if (level.vec().squaredNorm() == 0.0) return level;
  turn_world(performance.motion, level);
  for (std::array<Vec3, 2>& wrists : performance.true_wrists_ws) {
    for (Vec3& wrist : wrists) wrist = level * wrist;
  }
  for (Transform& heading : performance.true_headings_ws) {  // still a frame on the floor
    const Vec3 moved = level * heading.translation;
    heading = {yaw_rotation(heading_yaw(level * heading.rotation)),
               Vec3(moved.x(), 0.0, moved.z())};
  }
  return level;
}

Quat level_head_path_as_loaded(Performance& performance) {
  const Quat level = head_path_levelling(performance.motion, performance.roles[Role::kHead]);
  if (level.vec().squaredNorm() > 0.0) turn_world(performance.motion, level);
  return level;
}

Result<Performance> with_rig(Performance performance, std::shared_ptr<const Skeleton> rig,
                             const JointRoles& rig_roles) {
  Result<Clip> moved = retarget_clip(performance.motion, performance.roles, rig, rig_roles);
  if (!moved) return Error{"onto the rig " + rig_roles.convention + ": " + moved.error().message};
  performance.motion = std::move(moved).value();
  performance.roles = rig_roles;
  return performance;
}

namespace {

double standing_height_m(const Performance& performance) {
  return measure_body(performance.motion.skeleton(), performance.roles).standing_height_m;
}

// The performance on recipe.rig, sized there by recipe.body_scale; as it is without a rig.
Result<Performance> delivered(Performance performance, const PerformanceRecipe& recipe) {
  if (!recipe.rig) return performance;
  const double template_height_m = standing_height_m(performance);
  Result<Performance> moved = with_rig(std::move(performance), recipe.rig, recipe.rig_roles);
  if (!moved) return moved.error();
  // On another rig the body is sized after retargeting: retargeting onto the rig gives the rig's
  // own bone lengths, and a scale before it was lost (body-size@asf was clean@asf). The size is
  // the template dancer's times body_scale, not the rig's: a sweep of 1.1x on a 1.96 m rig was a
  // 1.23x body.
  const double rig_height_m = standing_height_m(moved.value());
  if (!recipe.body_scale || !(template_height_m > 0.0) || !(rig_height_m > 0.0)) return moved;
  return with_body_scale(std::move(moved).value(),
                         *recipe.body_scale * template_height_m / rig_height_m);
}

}  // namespace

Result<Performance> recorded_performance(Clip clip, const JointRoles& roles, int take,
                                         int take_frames, double template_rate_hz) {
  const double rate = clip.frame_rate();
  if (!(rate > 0.0) || !std::isfinite(rate)) return Error{"the recording has no frame rate"};
  if (!(template_rate_hz > 0.0) || !std::isfinite(template_rate_hz)) {
    return Error{"the take has no frame rate"};
  }
  if (take_frames < 2) return Error{"the take has fewer than 2 frames"};
  // The last frame whose moment is within the take.
  const double last_moment = static_cast<double>(take_frames - 1) / template_rate_hz;
  const int frames =
      std::min(clip.frame_count(), static_cast<int>(std::floor(last_moment * rate + 1e-9)) + 1);
  if (frames < 2) return Error{"the recording has fewer than 2 frames within the take"};
  Performance performance;
  clip.keep_first_frames(frames);
  performance.motion = std::move(clip);
  performance.roles = roles;
  performance.template_rate_hz = template_rate_hz;
  performance.times_s.resize(static_cast<std::size_t>(frames));
  performance.truth.resize(static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    const auto i = static_cast<std::size_t>(f);
    performance.times_s[i] = static_cast<double>(f) / rate;
    performance.truth[i].take = take;
    performance.truth[i].template_frame = static_cast<double>(f) * template_rate_hz / rate;
  }
  return performance;
}

Result<Performance> make_performance(std::span<const SourceTake> sources,
                                     const PerformanceRecipe& recipe, std::uint64_t seed) {
  if (!recipe.recorded && (sources.empty() || sources[0].clip == nullptr)) {
    return Error{"no take to perform from"};
  }
  if (!recipe.recorded && sources[0].clip->frame_count() >= 2) {
    const double frames = frames_bound(*sources[0].clip, recipe);
    if (!(frames <= static_cast<double>(kMaxClipFrames))) {
      return Error{fmt::format(
          "the performance would have up to {:.4g} frames, over the limit of {} frames per "
          "clip: ask for a shorter duration, a lower rate or a faster tempo",
          frames, kMaxClipFrames)};
    }
  }
  Performance performance;
  if (recipe.recorded) {
    performance = *recipe.recorded;
  } else if (recipe.improvise) {
    ImproviseOptions options = recipe.improvise_options;
    options.seed = derive_seed(seed, 10);
    Result<Performance> improvised = improvise(sources, options);
    if (!improvised) return improvised.error();
    performance = std::move(improvised).value();
  } else {
    if (sources[0].clip->frame_count() < 2) return Error{"the take has fewer than 2 frames"};
    PlayOptions options = recipe.play;
    options.seed = derive_seed(seed, 11);
    performance = play(sources[0], options);
  }
  if (recipe.body_scale && *recipe.body_scale != 1.0 && !recipe.rig)
    performance = with_body_scale(std::move(performance), *recipe.body_scale);
  if (recipe.room_yaw_rad != 0.0 || !recipe.room_offset_m.isZero()) {
    performance =
        with_room_placement(std::move(performance), recipe.room_yaw_rad, recipe.room_offset_m);
  }
  if (recipe.world_tilt_deg != 0.0) {
    performance = with_world_tilt(std::move(performance), recipe.world_tilt_deg);
  }
  // A sensor that stalls holds a pose the dancer has left, one that pops turns the trunk the
  // heading is read from: the partner is scored against the real body's place and hands
  // (Performance::true_headings_ws, true_wrists_ws), not the sensed ones.
  const bool senses_a_false_body =
      recipe.loss.freeze_every_s > 0.0 || recipe.noise.glitch_every_s > 0.0;
  if (recipe.noise.active()) {
    // The sensor's errors belong to the dancer's body, not to the skeleton the motion is delivered
    // on: they go in before retargeting, so every rig gets the same sensed performance. Put on
    // each joint of the delivered rig instead, a rig with more joints along a chain got more
    // error from the same sensor (the Bandai rig's root joint above its hips tilted the whole
    // body by a second calibration error; `suit-drift@bandai` 90.7 against 94.8 %).
    // docs/evaluation.md, "The sensor's errors on the body, not the rig".
    Result<Performance> truth = delivered(performance, recipe);  // noise-free, for the scores
    if (!truth) return truth.error();
    SensorNoiseOptions options = recipe.noise;
    options.seed = derive_seed(seed, 12);
    Result<Performance> noisy =
        delivered(with_sensor_noise(std::move(performance), options), recipe);
    if (!noisy) return noisy.error();
    performance = std::move(noisy).value();
    if (recipe.head_hands) {
      const Quat level = level_head_path_as_loaded(performance);
      if (level.vec().squaredNorm() > 0.0) turn_world(truth.value().motion, level);
    }
    record_true_wrists(truth.value());
    if (recipe.head_hands || senses_a_false_body) record_true_headings(truth.value());
    performance.true_wrists_ws = std::move(truth.value().true_wrists_ws);
    performance.true_headings_ws = std::move(truth.value().true_headings_ws);
  } else {
    Result<Performance> moved = delivered(std::move(performance), recipe);
    if (!moved) return moved.error();
    performance = std::move(moved).value();
    if (recipe.head_hands) level_head_path_as_loaded(performance);
    if (recipe.head_hands || senses_a_false_body) {
      record_true_wrists(performance);
      record_true_headings(performance);
    }
  }
  if (!recipe.head_hands) level_as_loaded(performance);
  if (recipe.head_hands) {
    if (recipe.told_head_height_factor > 0.0) {
      performance.told_head_height_m =
          recipe.told_head_height_factor * highest_head_m(performance.motion, performance.roles);
    }
    if (recipe.tell_arms_forward) {
      constexpr int kStride = 10;  // a median over every 10th frame
      Result<ArmsForward> arms =
          arms_forward_of_body(performance.motion, performance.roles, kStride);
      if (!arms) return arms.error();
      const Vec3& error = recipe.told_arms_forward_error;
      arms.value().wrists[0] += error;
      arms.value().wrists[1] += Vec3(-error.x(), error.y(), error.z());
      performance.told_arms_forward = arms.value();
    }
    PointNoiseOptions options = recipe.point_noise;
    options.seed = derive_seed(seed, 14);
    Result<Performance> points = with_head_hands(std::move(performance), options);
    if (!points) return points.error();
    performance = std::move(points).value();
  }
  if (recipe.loss.active()) {
    FrameLossOptions options = recipe.loss;
    options.seed = derive_seed(seed, 13);
    performance = with_frame_loss(std::move(performance), options);
  }
  return performance;
}

}  // namespace duet
