#include "duet/features/feature_extractor.h"

#include <cassert>
#include <algorithm>
#include <cmath>
#include <limits>

#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

bool all_finite(std::span<const Vec3> values) {
  for (const Vec3& v : values) {
    if (!v.allFinite()) return false;
  }
  return true;
}

bool all_finite(std::span<const Quat> values) {
  for (const Quat& q : values) {
    if (!q.coeffs().allFinite()) return false;
  }
  return true;
}

}  // namespace

void FeatureExtractor::Context::reset() noexcept {
  newest_ = -1;
  count_ = 0;
  place_noise_ = {};
  place_noise_time_s_ = 0.0;
  head_height_max_m_ = 0.0;
}

Result<FeatureExtractor> FeatureExtractor::create(std::shared_ptr<const Skeleton> skeleton,
                                                  const JointRoles& roles,
                                                  const FeatureSpec& spec) {
  if (!skeleton) return Error{"feature extractor: no skeleton"};
  if (!(spec.velocity_window_s > 0.0)) {
    return Error{"feature extractor: velocity window must be positive"};
  }
  const bool head_hands = spec.input_points == InputPoints::kHeadHands;
  // Every role the canonical points are built from, and every role the spec names.
  std::vector<Role> needed = {Role::kHead, Role::kLeftWrist, Role::kRightWrist};
  if (!head_hands) {
    needed = {Role::kHips,       Role::kLeftHip,      Role::kRightHip,
              Role::kLeftWrist,  Role::kRightWrist,   Role::kLeftAnkle,
              Role::kRightAnkle, Role::kLeftShoulder, Role::kRightShoulder};
    for (const BodySegment& segment : spec.posture_segments) {
      needed.push_back(segment.from);
      needed.push_back(segment.to);
    }
    for (Role role : spec.posture_points) needed.push_back(role);
  }
  std::string missing;
  for (Role role : needed) {
    const int joint = roles[role];
    if ((joint < 0 || joint >= skeleton->joint_count()) &&
        missing.find(role_name(role)) == std::string::npos) {
      if (!missing.empty()) missing += ", ";
      missing += role_name(role);
    }
  }
  if (!missing.empty()) {
    return Error{"feature extractor: the skeleton has no joint for role(s) " + missing};
  }
  FeatureExtractor extractor;
  if (head_hands) {
    Result<Quat> correction = rest_pose_correction(*skeleton, roles);
    if (!correction) return Error{"feature extractor: " + correction.error().message};
    extractor.head_correction_ = correction.value();
  } else {
    const BodyDimensions body = measure_body(*skeleton, roles);
    if (!(body.leg_length_m > 1e-3) || !std::isfinite(body.leg_length_m)) {
      return Error{"feature extractor: the skeleton's legs have no length (hip, knee and ankle "
                   "joints at one place?)"};
    }
    extractor.leg_length_m_ = body.leg_length_m;
  }
  extractor.spec_ = spec;
  extractor.roles_ = roles;
  extractor.effector_joints_ = {roles[Role::kLeftWrist], roles[Role::kRightWrist],
                                roles[Role::kLeftAnkle], roles[Role::kRightAnkle]};
  if (head_hands) extractor.effector_joints_[2] = extractor.effector_joints_[3] = -1;
  extractor.skeleton_ = std::move(skeleton);
  return extractor;
}

FeatureExtractor::Context FeatureExtractor::make_context() const {
  Context context;
  context.positions_ws_.resize(static_cast<std::size_t>(skeleton_->joint_count()));
  context.rotations_ws_.resize(static_cast<std::size_t>(skeleton_->joint_count()));
  return context;
}

Vec3 FeatureExtractor::body_point(std::span<const Vec3> positions_ws, Role role) const noexcept {
  auto at = [&](Role r) { return positions_ws[static_cast<std::size_t>(roles_[r])]; };
  if (role == Role::kHips) return pelvis_centre(positions_ws, roles_);
  if (role == Role::kChest) return 0.5 * (at(Role::kLeftShoulder) + at(Role::kRightShoulder));
  return at(role);
}

Vec3 FeatureExtractor::standard_hand(std::span<const Vec3> positions_ws,
                                     std::size_t side) const noexcept {
  using A = StandardArm;
  struct Link {
    Role from, to;
    double length;
  };
  // Each hand's chain from the pelvis centre (BodySegment's canonical kHips and kChest).
  static constexpr std::array<std::array<Link, 4>, 2> kArms = {{
      {{{Role::kHips, Role::kChest, A::kTrunk},
        {Role::kChest, Role::kLeftShoulder, A::kHalfShoulders},
        {Role::kLeftShoulder, Role::kLeftElbow, A::kUpperArm},
        {Role::kLeftElbow, Role::kLeftWrist, A::kForearm}}},
      {{{Role::kHips, Role::kChest, A::kTrunk},
        {Role::kChest, Role::kRightShoulder, A::kHalfShoulders},
        {Role::kRightShoulder, Role::kRightElbow, A::kUpperArm},
        {Role::kRightElbow, Role::kRightWrist, A::kForearm}}},
  }};
  Vec3 hand = Vec3::Zero();
  for (const Link& link : kArms[side]) {
    const Vec3 delta = body_point(positions_ws, link.to) - body_point(positions_ws, link.from);
    const double length = delta.norm();
    if (length > 1e-9) hand += (link.length / length) * delta;
  }
  return hand;
}

void FeatureExtractor::extract(Context& context, std::span<const Vec3> translations_ls,
                               std::span<const Quat> rotations_ls, double time_s,
                               std::span<float> out) const noexcept {
  assert(out.size() == static_cast<std::size_t>(dimension()));
  assert(translations_ls.size() == context.positions_ws_.size());
  if (!std::isfinite(time_s) || !all_finite(translations_ls) || !all_finite(rotations_ls)) {
    for (float& v : out) v = std::numeric_limits<float>::quiet_NaN();
    return;
  }
  forward_kinematics(*skeleton_, translations_ls, rotations_ls, context.positions_ws_,
                     context.rotations_ws_);
  const Context::Sample now = spec_.input_points == InputPoints::kHeadHands
                                  ? extract_head_hands(context, time_s, out)
                                  : extract_full_body(context, time_s, out);
  remember(context, now);
  refresh_place_noise(context);
}

void FeatureExtractor::refresh_place_noise(Context& context) const noexcept {
  if (!debiases_speeds()) return;
  // The noise changes slowly, and its median costs more than the rest of the frame's features:
  // read again every kEveryS once known, on every frame until then.
  constexpr double kEveryS = 0.1;
  const double newest_s = context.sample(0).time_s;
  const bool known = context.place_noise_ != std::array<double, 4>{};
  if (known && newest_s - context.place_noise_time_s_ < kEveryS &&
      newest_s >= context.place_noise_time_s_) {
    return;
  }
  context.place_noise_ = place_noise_energies(context, 4);
  context.place_noise_time_s_ = newest_s;
}

FeatureExtractor::Context::Sample FeatureExtractor::extract_full_body(
    const Context& context, double time_s, std::span<float> out) const noexcept {
  const std::span<const Vec3> positions(context.positions_ws_);
  Context::Sample now;
  now.time_s = time_s;
  now.root = pelvis_centre(positions, roles_);
  now.yaw = body_heading_yaw(positions, roles_);
  for (std::size_t e = 0; e < 4; ++e) {
    const bool hand = e < 2;
    now.effectors[e] = spec_.standard_arm_speeds && hand
                           ? Vec3(now.root + leg_length_m_ * standard_hand(positions, e))
                           : positions[static_cast<std::size_t>(effector_joints_[e])];
  }
  if (spec_.debiased_speeds) note_second_differences(context, now);
  const Quat to_heading = yaw_rotation(-now.yaw);
  const double per_leg = 1.0 / leg_length_m_;

  // Posture: segment directions and effector positions, in the heading frame (x left, y up,
  // z forward).
  std::size_t d = 0;
  auto put = [&](const Vec3& v) {
    for (int k = 0; k < 3; ++k) out[d++] = static_cast<float>(v[k]);
  };
  for (const BodySegment& segment : spec_.posture_segments) {
    const Vec3 delta = body_point(positions, segment.to) - body_point(positions, segment.from);
    const double length = delta.norm();
    put(length > 1e-9 ? Vec3(to_heading * (delta / length)) : Vec3::Zero());
  }
  for (Role role : spec_.posture_points) {
    put(to_heading * (body_point(positions, role) - now.root) * per_leg);
  }

  put_velocities(context, now, to_heading, per_leg, 4, out.subspan(d));
  return now;
}

FeatureExtractor::Context::Sample FeatureExtractor::extract_head_hands(
    Context& context, double time_s, std::span<float> out) const noexcept {
  const auto at = [&](Role role) { return static_cast<std::size_t>(roles_[role]); };
  const Vec3 head = context.positions_ws_[at(Role::kHead)];
  const Quat head_canonical = context.rotations_ws_[at(Role::kHead)] * head_correction_;
  Context::Sample now;
  now.time_s = time_s;
  now.root = head;
  now.yaw = heading_yaw(head_canonical);
  now.effectors[0] = context.positions_ws_[at(Role::kLeftWrist)];
  now.effectors[1] = context.positions_ws_[at(Role::kRightWrist)];
  // Lengths in head heights: the one a calibration gave, else the highest the head has held,
  // which a dancer reaches standing in the first moments (a floor keeps a first frame on the
  // ground from dividing by ~0).
  constexpr double kLowestHeadHeightM = 0.5;
  context.head_height_max_m_ =
      std::max({context.head_height_max_m_, held_head_height(context, head.y(), time_s),
                kLowestHeadHeightM});
  const double per_height = 1.0 / context.head_height_m();
  const Quat to_heading = yaw_rotation(-now.yaw);

  std::size_t d = 0;
  auto put = [&](const Vec3& v) {
    for (int k = 0; k < 3; ++k) out[d++] = static_cast<float>(v[k]);
  };
  put(to_heading * (now.effectors[0] - head) * per_height - context.hand_offsets_[0]);
  put(to_heading * (now.effectors[1] - head) * per_height - context.hand_offsets_[1]);
  out[d++] = static_cast<float>(head.y() * per_height);
  if (spec_.head_tilt) put(to_heading * (head_canonical * Vec3::UnitY()));  // nod and roll

  put_velocities(context, now, to_heading, per_height, 2, out.subspan(d));
  return now;
}

void FeatureExtractor::put_velocities(const Context& context, const Context::Sample& now,
                                      const Quat& to_heading, double per_unit, int effectors,
                                      std::span<float> out) const noexcept {
  Vec3 root_velocity_heading = Vec3::Zero();
  double yaw_rate = 0.0;
  std::array<double, 4> effector_speed{};
  const bool debias = debiases_speeds();
  if (const Context::Sample* reference = velocity_reference(context, now.time_s)) {
    const double dt = now.time_s - reference->time_s;
    root_velocity_heading = to_heading * ((now.root - reference->root) * (per_unit / dt));
    yaw_rate = wrap_angle(now.yaw - reference->yaw) / dt;
    const std::array<double, 4>& noise = context.place_noise_;
    const double allowance = spec_.speed_noise_allowance_m * spec_.speed_noise_allowance_m;
    for (std::size_t e = 0; e < static_cast<std::size_t>(effectors); ++e) {
      double squared = (now.effectors[e] - reference->effectors[e]).squaredNorm();
      // A speed is a length, so a sensor's white noise only ever adds to it: its expected share
      // of the squared difference, less what a clean capture reads, is taken off
      // (FeatureSpec::debiased_speeds).
      if (debias) squared = std::max(0.0, squared - std::max(0.0, noise[e] - allowance));
      effector_speed[e] = std::sqrt(squared) * per_unit / dt;
    }
  }
  std::size_t d = 0;
  out[d++] = static_cast<float>(root_velocity_heading.z());  // forward
  out[d++] = static_cast<float>(root_velocity_heading.x());  // lateral
  out[d++] = static_cast<float>(root_velocity_heading.y());  // vertical
  out[d++] = static_cast<float>(yaw_rate);
  for (int e = 0; e < effectors; ++e) {
    out[d++] = static_cast<float>(effector_speed[static_cast<std::size_t>(e)]);
  }
}

void FeatureExtractor::note_second_differences(const Context& context,
                                               Context::Sample& now) noexcept {
  // p(t) - 2 p(t - 1) + p(t - 2) over three evenly spaced frames (intervals within 10 % of each
  // other): white noise of sigma per axis gives it 18 sigma^2 in expectation, a dance's own
  // acceleration a dt^2 (about 3 mm at 60 Hz for a hand turning fast), so it reads the noise.
  constexpr double kEvenSpacing = 0.1;
  now.second_differences.fill(std::numeric_limits<double>::quiet_NaN());
  if (context.count_ < 2) return;
  const Context::Sample& middle = context.sample(0);
  const Context::Sample& older = context.sample(1);
  const double later = now.time_s - middle.time_s;
  const double earlier = middle.time_s - older.time_s;
  if (!(later > 0.0 && earlier > 0.0 && std::abs(later - earlier) <= kEvenSpacing * earlier)) {
    return;
  }
  for (std::size_t e = 0; e < now.effectors.size(); ++e) {
    now.second_differences[e] =
        (now.effectors[e] - 2.0 * middle.effectors[e] + older.effectors[e]).squaredNorm();
  }
}

std::array<double, 4> FeatureExtractor::place_noise_energies(const Context& context,
                                                             int effectors) noexcept {
  // The median of the second differences over the last kWindowS, which a sharp turn of the hand
  // does not move; a chi-square of 3 degrees of freedom has its median at 0.789 of its mean.
  constexpr double kWindowS = 0.5;
  constexpr double kMedianToMean = 1.0 / 0.789;
  // Too few to tell the noise from a take's first frames (the salsa BVHs ramp in from a rest
  // pose over four frames): nothing is read.
  constexpr std::size_t kFewest = 5;
  const auto count = static_cast<std::size_t>(effectors);
  std::array<std::array<double, Context::kHistory>, 4> energies;
  std::array<std::size_t, 4> n{};
  const double newest_s = context.sample(0).time_s;
  for (int age = 0; age < context.count_; ++age) {
    const Context::Sample& sample = context.sample(age);
    if (!(newest_s - sample.time_s <= kWindowS)) break;
    for (std::size_t e = 0; e < count; ++e) {
      if (std::isfinite(sample.second_differences[e])) {
        energies[e][n[e]++] = sample.second_differences[e];
      }
    }
  }
  std::array<double, 4> noise{};
  for (std::size_t e = 0; e < count; ++e) {
    if (n[e] < kFewest) continue;
    const auto begin = energies[e].begin();
    const auto mid = begin + static_cast<std::ptrdiff_t>(n[e] / 2);
    std::nth_element(begin, mid, begin + static_cast<std::ptrdiff_t>(n[e]));
    // 18 sigma^2 in a second difference, 6 sigma^2 in a plain one.
    noise[e] = *mid * kMedianToMean / 3.0;
  }
  return noise;
}

const FeatureExtractor::Context::Sample* FeatureExtractor::velocity_reference(
    const Context& context, double time_s) const noexcept {
  const Context::Sample* reference = nullptr;
  for (int age = 0; age < context.count_; ++age) {
    const Context::Sample& sample = context.sample(age);
    if (sample.time_s >= time_s) continue;  // out-of-order timestamps carry no velocity
    reference = &sample;
    if (time_s - sample.time_s >= spec_.velocity_window_s) break;
  }
  return reference;
}

double FeatureExtractor::held_head_height(const Context& context, double head_y,
                                          double time_s) noexcept {
  // The median over a window, not the frame's own height: a hop, a moment on tiptoe or a
  // sensor's spike would otherwise only ever raise the unit (one 0.1 s rise of 7 % kept a
  // retargeted take lost for 11 s; docs/features.md, three points' unit).
  constexpr double kHeldS = 0.3;
  std::array<double, Context::kHistory + 1> heights;
  std::size_t n = 0;
  if (std::isfinite(head_y)) heights[n++] = head_y;
  for (int age = 0; age < context.count_; ++age) {
    const Context::Sample& sample = context.sample(age);
    if (!(time_s - sample.time_s < kHeldS)) break;
    if (std::isfinite(sample.root.y())) heights[n++] = sample.root.y();
  }
  if (n == 0) return 0.0;
  const auto middle = heights.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(heights.begin(), middle, heights.begin() + static_cast<std::ptrdiff_t>(n));
  return *middle;
}

void FeatureExtractor::remember(Context& context, const Context::Sample& sample) noexcept {
  context.newest_ = (context.newest_ + 1) % Context::kHistory;
  context.history_[static_cast<std::size_t>(context.newest_)] = sample;
  if (context.count_ < Context::kHistory) ++context.count_;
}

FeatureMatrix FeatureExtractor::extract_clip(const Clip& clip) const {
  FeatureMatrix rows(clip.frame_count(), dimension());
  Context context = make_context();
  for (int f = 0; f < clip.frame_count(); ++f) {
    extract(context, clip.translations_ls(f), clip.rotations_ls(f), f / clip.frame_rate(),
            std::span<float>(rows.row(f).data(), static_cast<std::size_t>(dimension())));
  }
  return rows;
}

FeatureNormalizer FeatureNormalizer::fit(const FeatureMatrix& raw, const FeatureSpec& spec) {
  const auto dims = raw.cols();
  FeatureNormalizer normalizer;
  normalizer.mean_ = Eigen::VectorXf::Zero(dims);
  normalizer.scale_ = Eigen::VectorXf::Ones(dims);
  if (raw.rows() == 0) return normalizer;
  const Eigen::VectorXd mean = raw.cast<double>().colwise().mean().transpose();
  const Eigen::MatrixXd centred = raw.cast<double>().rowwise() - mean.transpose();
  const Eigen::VectorXd std_dev =
      (centred.array().square().colwise().sum() / static_cast<double>(raw.rows()))
          .sqrt()
          .transpose();
  normalizer.mean_ = mean.cast<float>();
  for (int b = 0; b < kFeatureBlockCount; ++b) {
    const auto block = static_cast<FeatureBlock>(b);
    const double weight = block == FeatureBlock::kPosture        ? spec.posture_block_weight()
                          : block == FeatureBlock::kRootVelocity ? spec.root_velocity_weight
                                                                 : spec.effector_speed_weight;
    const int begin = spec.block_begin(block);
    const int size = spec.block_size(block);
    for (int d = begin; d < begin + size; ++d) {
      double floor = spec.speed_std_floor;
      if (block == FeatureBlock::kPosture) floor = spec.posture_std_floor;
      if (block == FeatureBlock::kRootVelocity && d == begin + 3) {
        floor = spec.yaw_rate_std_floor_radps;
      }
      const double deviation = std::max(std_dev[d], floor);
      normalizer.scale_[d] = static_cast<float>(weight / (std::sqrt(double(size)) * deviation));
    }
  }
  return normalizer;
}

void FeatureNormalizer::apply(std::span<float> features) const noexcept {
  assert(features.size() == static_cast<std::size_t>(mean_.size()));
  for (std::size_t d = 0; d < features.size(); ++d) {
    const auto i = static_cast<Eigen::Index>(d);
    features[d] = (features[d] - mean_[i]) * scale_[i];
  }
}

void FeatureNormalizer::apply(FeatureMatrix& rows) const {
  rows = (rows.rowwise() - mean_.transpose()).array().rowwise() * scale_.transpose().array();
}

}  // namespace duet
