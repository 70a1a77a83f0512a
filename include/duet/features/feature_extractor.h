// Feature extraction, one frame at a time (the live path) or a whole clip (offline); both give
// the same numbers because the clip version runs the per-frame one.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_spec.h"
#include "duet/motion/clip.h"

namespace duet {

// One row per frame, row-major float (the follower streams through rows).
using FeatureMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

class FeatureExtractor {
 public:
  // Checks that every role the spec needs exists in the skeleton and that its legs have a length
  // (the body's scale). The skeleton's lengths must be in metres (load_motion does that), though
  // the features themselves do not depend on units or body size.
  static Result<FeatureExtractor> create(std::shared_ptr<const Skeleton> skeleton,
                                         const JointRoles& roles, const FeatureSpec& spec);

  // What the extractor remembers between frames: recent root and effector positions for the
  // velocity window, and forward-kinematics scratch. Sized once; reset() at a new performance.
  class Context {
   public:
    void reset() noexcept;
    // Head and hands: the user's head height standing (metres), known from a calibration, as the
    // unit of lengths; 0 (the default) learns it, as the highest the head has held. Kept across
    // reset().
    void set_head_height(double head_height_m) noexcept { head_height_known_m_ = head_height_m; }
    // The calibration's height (0: none) and the unit of lengths in use: the calibration's, else
    // the highest the head has held (0 before the first frame).
    double known_head_height_m() const noexcept { return head_height_known_m_; }
    double head_height_m() const noexcept {
      return head_height_known_m_ > 0.0 ? head_height_known_m_ : head_height_max_m_;
    }
    // Head and hands: where the user's body holds each hand (left, right) against where the
    // template dancers' hold it in the same pose, in head heights in the heading frame (x left,
    // y up, z forward): taken off the hands' places (arms_forward.h). Zero (the default): none.
    // Kept across reset().
    void set_hand_offsets(const std::array<Vec3, 2>& offsets) noexcept { hand_offsets_ = offsets; }
    const std::array<Vec3, 2>& hand_offsets() const noexcept { return hand_offsets_; }

   private:
    friend class FeatureExtractor;
    struct Sample {
      double time_s = 0.0;
      Vec3 root = Vec3::Zero();  // the pelvis centre (full body) or the head (head and hands)
      double yaw = 0.0;
      std::array<Vec3, 4> effectors;  // left hand, right hand, left foot, right foot
      // Per effector: the squared second difference of its place ending at this frame
      // (note_second_differences); NaN where the frames were not evenly spaced.
      std::array<double, 4> second_differences{};
    };
    static constexpr int kHistory = 64;  // enough for a 0.1 s window at 600 Hz
    // The remembered sample `age` frames before the newest (0: the newest; age < count_).
    const Sample& sample(int age) const noexcept {
      return history_[static_cast<std::size_t>((newest_ - age + kHistory) % kHistory)];
    }
    std::array<Sample, kHistory> history_{};
    int newest_ = -1;
    int count_ = 0;
    // FeatureSpec::debiased_speeds: each effector's place noise (place_noise_energies) as last
    // read, at place_noise_time_s_; all zero until known.
    std::array<double, 4> place_noise_{};
    double place_noise_time_s_ = 0.0;
    // Head and hands: the highest the head has held (metres; held_head_height), the unit of
    // lengths there, since a headset says nothing of the body's size.
    double head_height_max_m_ = 0.0;
    double head_height_known_m_ = 0.0;  // set_head_height; 0: learnt
    std::array<Vec3, 2> hand_offsets_{Vec3::Zero(), Vec3::Zero()};  // set_hand_offsets
    std::vector<Vec3> positions_ws_;
    std::vector<Quat> rotations_ws_;
  };

  Context make_context() const;
  // The body's leg length (metres): the unit of the position and velocity features of the full
  // body (0 for head-and-hands features, whose unit is the head's height).
  double leg_length_m() const { return leg_length_m_; }
  int dimension() const { return spec_.dimension(); }
  const FeatureSpec& spec() const { return spec_; }

  // Raw (not yet standardised) features of one frame at time `time_s` (seconds, increasing).
  // A pose with NaN/inf gives NaN features and is not remembered, so it cannot poison the
  // velocities of later frames. Allocates nothing.
  void extract(Context& context, std::span<const Vec3> translations_ls,
               std::span<const Quat> rotations_ls, double time_s,
               std::span<float> out) const noexcept;

  // Raw features of every frame of a clip (a fresh context, frame times from the clip's rate).
  FeatureMatrix extract_clip(const Clip& clip) const;

  // Head and hands from a full-body rig: the head's correction, which create() reads from the
  // rest pose. A template gives head_correction(clip, roles) here, right also for a rig whose
  // rest pose does not stand.
  void set_head_correction(const Quat& correction) noexcept { head_correction_ = correction; }

 private:
  FeatureExtractor() = default;
  // A role's point in the canonical body (see BodySegment): the pelvis centre for kHips, the
  // shoulder centre for kChest, else the role's joint.
  Vec3 body_point(std::span<const Vec3> positions_ws, Role role) const noexcept;
  // A hand (side 0 left, 1 right) relative to the pelvis centre, in leg lengths and world axes,
  // rebuilt along StandardArm from the directions of its chain (FeatureSpec::standard_arm_speeds).
  Vec3 standard_hand(std::span<const Vec3> positions_ws, std::size_t side) const noexcept;
  // The two layouts of FeatureSpec::InputPoints, from the world pose of `context`; both return
  // the sample to remember.
  Context::Sample extract_full_body(const Context& context, double time_s,
                                    std::span<float> out) const noexcept;
  Context::Sample extract_head_hands(Context& context, double time_s,
                                     std::span<float> out) const noexcept;
  // The newest remembered sample at least velocity_window_s older than time_s, else the oldest
  // (the first frames of a performance); null when there is none.
  const Context::Sample* velocity_reference(const Context& context, double time_s) const noexcept;
  static void remember(Context& context, const Context::Sample& sample) noexcept;
  // The level the head holds: the median of its height at `time_s` (head_y) and at the
  // remembered frames of the last 0.3 s (the last Context::kHistory frames above 213 Hz).
  static double held_head_height(const Context& context, double head_y, double time_s) noexcept;
  // FeatureSpec::debiased_speeds: the squared second difference of each effector's place over
  // `now` and the two newest remembered frames, when the three are evenly spaced.
  static void note_second_differences(const Context& context, Context::Sample& now) noexcept;
  // The white noise the first `effectors` effectors' places carry, over the remembered frames: the
  // expected squared length it adds to the difference of two of an effector's places (metres^2), 6
  // sigma^2 for a sigma per axis, from the median second difference over the last 0.5 s; 0 with
  // fewer than five.
  static std::array<double, 4> place_noise_energies(const Context& context, int effectors) noexcept;
  // Context::place_noise_ from the remembered frames (the newest is the frame just extracted), at
  // most every 0.1 s once known.
  void refresh_place_noise(Context& context) const noexcept;
  // FeatureSpec::debiased_speeds, which applies to the full body only.
  bool debiases_speeds() const noexcept {
    return spec_.debiased_speeds && spec_.input_points == InputPoints::kFullBody;
  }
  // The velocity blocks: the root's velocity in the heading frame and the yaw rate, then the
  // speeds of the first `effectors` effectors, lengths times per_unit (FeatureSpec).
  void put_velocities(const Context& context, const Context::Sample& now, const Quat& to_heading,
                      double per_unit, int effectors, std::span<float> out) const noexcept;

  FeatureSpec spec_;
  JointRoles roles_;
  double leg_length_m_ = 1.0;
  std::array<int, 4> effector_joints_{};
  // Head and hands: R_canonical = R_world * head_correction_ for the head (head_hands.h).
  Quat head_correction_ = Quat::Identity();
  std::shared_ptr<const Skeleton> skeleton_;
};

// Standardisation with the template's statistics (method.md 3): (x - mean) / max(std, floor),
// times the block weight / sqrt(block dimension).
class FeatureNormalizer {
 public:
  // Fits mean and deviation over the rows of `raw` (the template library).
  static FeatureNormalizer fit(const FeatureMatrix& raw, const FeatureSpec& spec);
  void apply(std::span<float> features) const noexcept;
  void apply(FeatureMatrix& rows) const;

  const Eigen::VectorXf& mean() const { return mean_; }
  const Eigen::VectorXf& scale() const { return scale_; }

 private:
  Eigen::VectorXf mean_;
  Eigen::VectorXf scale_;  // weight / (sqrt(block dims) * max(std, floor))
};

}  // namespace duet
