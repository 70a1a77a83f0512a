// What the feature vector phi_t holds (method.md 3, paper eq. 1-3), as weighted blocks:
//   [ posture | root velocity | effector speed ]
// posture: the log map (rotation vector) of each listed joint's local rotation; root velocity:
// forward, lateral and vertical velocity in the body's heading frame (m/s) plus the yaw rate
// (rad/s); effector speed: speeds of both hands and both feet (m/s).
#pragma once

#include <vector>

#include "duet/motion/skeleton_map.h"

namespace duet {

enum class FeatureBlock : int { kPosture, kRootVelocity, kEffectorSpeed, kCount };
constexpr int kFeatureBlockCount = static_cast<int>(FeatureBlock::kCount);

struct FeatureSpec {
  // Joints whose local rotation is a posture feature. The root is left out (its rotation is the
  // body's place in the room); fingers, eyes and toes carry no CMU data.
  std::vector<Role> posture_roles = {
      Role::kSpine,         Role::kChest,      Role::kNeck,       Role::kHead,
      Role::kLeftShoulder,  Role::kLeftElbow,  Role::kLeftWrist,  Role::kRightShoulder,
      Role::kRightElbow,    Role::kRightWrist, Role::kLeftHip,    Role::kLeftKnee,
      Role::kLeftAnkle,     Role::kRightHip,   Role::kRightKnee,  Role::kRightAnkle};

  // Block weights. After standardisation each block is also divided by sqrt(its dimension), so a
  // weight is the block's share of the squared distance whatever its size.
  double posture_weight = 1.0;
  // Velocities carry most of a sensor's noise: 0.3 (against 0.6) took noisy input from 98.5% to
  // 99.8% of frames within 100 ms in `duet eval` (docs/evaluation.md).
  double root_velocity_weight = 0.3;
  double effector_speed_weight = 0.3;

  // Velocities are differences over at least this much real time (not one frame): a live sensor
  // jitters by millimetres per frame, which a 1/120 s difference would turn into large speeds.
  // The same window at every input rate keeps the features rate-independent.
  double velocity_window_s = 0.1;

  // Floors on the template's standard deviation per dimension, so a joint that never moves in the
  // template does not turn sensor noise into huge standardised distances.
  double rotation_std_floor_rad = 0.05;
  double speed_std_floor_mps = 0.05;
  double yaw_rate_std_floor_radps = 0.2;

  int posture_dims() const { return 3 * static_cast<int>(posture_roles.size()); }
  static constexpr int kRootVelocityDims = 4;
  static constexpr int kEffectorSpeedDims = 4;
  int dimension() const { return posture_dims() + kRootVelocityDims + kEffectorSpeedDims; }
  // First dimension and size of a block.
  int block_begin(FeatureBlock block) const;
  int block_size(FeatureBlock block) const;
};

}  // namespace duet
