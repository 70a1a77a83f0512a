// What the feature vector phi_t holds (method.md 3, paper eq. 1-3), as weighted blocks:
//   [ posture | root velocity | effector speed ]
// computed in a canonical body space (issue 10), so the same dance gives the same features on any
// rig: nothing depends on joint names, rest poses, joint-local axes, the number of bones between
// two roles, units or body size.
//   posture: the world direction of body segments between roles (unit vectors) and the positions
//            of the hands and feet relative to the pelvis centre (in leg lengths), both in the
//            body's heading frame (x left, y up, z forward);
//   root velocity: forward, lateral and vertical velocity of the pelvis centre in the heading
//            frame (leg lengths per second) plus the heading's yaw rate (rad/s);
//   effector speed: speeds of both hands and both feet (leg lengths per second; a hand's along
//            a standard arm, FeatureSpec::standard_arm_speeds).
// The heading comes from the hip joints' positions (duet::body_heading_yaw), the leg length from
// the skeleton's bones (duet::measure_body).
#pragma once

#include <array>
#include <string_view>
#include <vector>

#include "duet/motion/skeleton_map.h"

namespace duet {

enum class FeatureBlock : int { kPosture, kRootVelocity, kEffectorSpeed, kCount };

// Which points of the body the features see. kHeadHands (issue 12) is what a VR headset and two
// controllers give: the head's and both hands' positions and the head's orientation. The library's
// templates then give the same three points from their head and wrist roles (docs/features.md,
// "Three points").
enum class InputPoints { kFullBody, kHeadHands };
// "full" | "head,hands" (the command line's --input-points).
bool parse_input_points(std::string_view text, InputPoints& points);
const char* input_points_name(InputPoints points);
constexpr int kFeatureBlockCount = static_cast<int>(FeatureBlock::kCount);

// A body segment from one role's point to another's. Two roles stand for canonical points rather
// than their joints, whose place differs between rigs: kHips is the pelvis centre (midpoint of the
// two thigh joints) and kChest the shoulder centre (midpoint of the two upper-arm joints).
struct BodySegment {
  Role from;
  Role to;
};

// A standard adult's arm, in leg lengths (hip to knee to ankle = 1), from Winter's anthropometric
// proportions of the standing height H: thigh 0.245 H and shank 0.246 H (the leg, 0.491 H), upper
// arm 0.186 H, forearm 0.146 H, shoulder width 0.259 H, shoulder joint 0.818 H and hip joint
// 0.530 H above the floor (D. A. Winter, Biomechanics and Motor Control of Human Movement, 4th
// ed., fig. 4.1). FeatureSpec::standard_arm_speeds measures the hands' speeds along it.
struct StandardArm {
  static constexpr double kTrunk = 0.587;          // pelvis centre to shoulder centre
  static constexpr double kHalfShoulders = 0.264;  // shoulder centre to each shoulder joint
  static constexpr double kUpperArm = 0.379;
  static constexpr double kForearm = 0.297;
};

struct FeatureSpec {
  InputPoints input_points = InputPoints::kFullBody;

  // Segments whose direction is a posture feature: the trunk, neck and head, the shoulder line
  // (the chest's twist against the hips), and the four limbs' two long bones each.
  std::vector<BodySegment> posture_segments = {
      {Role::kHips, Role::kChest},
      {Role::kRightShoulder, Role::kLeftShoulder},
      {Role::kLeftShoulder, Role::kLeftElbow},   {Role::kLeftElbow, Role::kLeftWrist},
      {Role::kRightShoulder, Role::kRightElbow}, {Role::kRightElbow, Role::kRightWrist},
      {Role::kLeftHip, Role::kLeftKnee},         {Role::kLeftKnee, Role::kLeftAnkle},
      {Role::kRightHip, Role::kRightKnee},       {Role::kRightKnee, Role::kRightAnkle}};
  // Effectors whose position relative to the pelvis centre is a posture feature.
  std::vector<Role> posture_points = {Role::kLeftWrist, Role::kRightWrist, Role::kLeftAnkle,
                                      Role::kRightAnkle};

  // Full body: a hand's speed is measured on a hand rebuilt from the directions of the trunk, half
  // the shoulder line, the upper arm and the forearm laid along StandardArm, not on the rig's own
  // hand. A hand's speed is mostly the arm's and the trunk's turn times the arm's length and the
  // shoulders' width, which are where rigs differ most (the CMU ASF fit's shoulder joints stand 44
  // cm apart, the salsa BVH's 23: the same sway of a standing dancer moved its hands twice as fast
  // in leg lengths), and a standing start is told from another take's by little else: on the ASF
  // rig takes 60_13 and 60_15 were followed on other takes' standing starts for 2-3 s (`clean@asf`
  // 98.85 % within 100 ms, 99.98 with it). The feet's speeds are the leg's own (the leg is the
  // unit), and the hands' and feet's places stay measured: a recording of the same body on another
  // rig (take 01 from the CMU ASF/AMC) has its hands where the body's are but its bones turned
  // otherwise, and rebuilt places took it from 99.8 to 93 %. docs/evaluation.md, "A hand's speed
  // on a standard arm". false: measured on the rig's hand.
  bool standard_arm_speeds = true;
  // Full body: effector speeds less the sensor's white noise. A speed is a length, so noise only
  // adds to it: under 3 degrees per joint the noise's share of a hand's or foot's place
  // difference over the velocity window is 57 / 81 mm in the median, more than a dancing hand
  // moves (76 mm) and three times a foot (27 mm), so a dancer standing still looked like one
  // stepping. That share, read from the effector's own second differences over the last 0.5 s
  // (FeatureExtractor::place_noise_energies), is taken off the squared difference before the root.
  // Signed velocities are left as they are: noise widens them but does not move them. Three
  // points' hands are the controllers' own places, millimetres of noise, and stay raw (measured:
  // no gain; docs/evaluation.md, "Speeds less the sensor's noise"). false: the raw speeds.
  bool debiased_speeds = true;
  // ... less what a clean capture reads, as the noise's share of a difference (sqrt(6) sigma for
  // a sigma per axis), in metres: the salsa takes' own jitter and a fast hand's turn read 1-2 mm
  // in the median and under 8 mm on 99 % of frames, so clean input keeps its speeds.
  double speed_noise_allowance_m = 0.01;

  // Block weights. After standardisation each block is also divided by sqrt(its dimension), so a
  // weight is the block's share of the squared distance whatever its size.
  double posture_weight = 1.0;
  // Velocities carry most of a sensor's noise: 0.3 (against 0.6) took noisy input from 98.5% to
  // 99.8% of frames within 100 ms in `duet eval` (docs/evaluation.md).
  double root_velocity_weight = 0.3;
  double effector_speed_weight = 0.3;
  // Three points (kHeadHands) weigh their posture block (the hands relative to the head, the
  // head's height) by this instead of posture_weight. Those positions are where a rig puts its
  // head and wrist joints (or a headset its eyes and a controller its grip): on the original CMU
  // ASF fit of take 01 the hands sit 10 cm wider and 9 cm lower below the head than on the
  // library's BVH, 0.4-0.95 standard deviations per dimension, and at weight 1 that recording was
  // followed on 36 % of frames, 94 % lost. 0.5: 92 % (docs/evaluation.md, "Three points on
  // another rig"), at a price: the Bandai dance and wave as three points are lost on 85 / 80 % of
  // frames (0.7: 100 / 97.5 %, the recording 78 %); below 0.5 they pass for salsa.
  double head_hands_posture_weight = 0.5;
  // The posture block's weight for these input points.
  double posture_block_weight() const {
    return input_points == InputPoints::kHeadHands ? head_hands_posture_weight : posture_weight;
  }

  // Velocities are differences over at least this much real time (not one frame): a live sensor
  // jitters by millimetres per frame, which a 1/120 s difference would turn into large speeds.
  // The same window at every input rate keeps the features rate-independent.
  double velocity_window_s = 0.1;

  // Floors on the template's standard deviation per dimension, so a dimension that never moves in
  // the template does not turn sensor noise into huge standardised distances. Posture: unit-vector
  // components and leg lengths (0.05 is about 3 degrees, or 4-5 cm on an adult); speeds: leg
  // lengths per second.
  double posture_std_floor = 0.05;
  double speed_std_floor = 0.05;
  double yaw_rate_std_floor_radps = 0.2;

  // Head and hands: both hands relative to the head (6), the head's height (1) and, with
  // head_tilt, its up direction (3), all in the head's heading frame.
  bool head_tilt = false;
  int posture_dims() const {
    if (input_points == InputPoints::kHeadHands) return head_tilt ? 10 : 7;
    return 3 * static_cast<int>(posture_segments.size() + posture_points.size());
  }
  // Forward, lateral and vertical velocity of the root (the pelvis centre, or the head) and the
  // heading's yaw rate.
  static constexpr int kRootVelocityDims = 4;
  // Speeds of the hands and feet (full body) or of the hands (head and hands).
  int effector_speed_dims() const { return input_points == InputPoints::kHeadHands ? 2 : 4; }
  int velocity_dims() const { return kRootVelocityDims + effector_speed_dims(); }
  int dimension() const { return posture_dims() + velocity_dims(); }
  // The posture dimensions of each limb: an arm's are its upper arm's and forearm's directions
  // and its hand's position, a leg's likewise (a segment counts when both its roles are the
  // limb's). The emission bounds the share of a limb far out of line with the others
  // (FollowParams::limb_outlier_ratio): a live system holds an arm whose markers the partner
  // hides. Empty for three points, whose hands are the whole posture.
  std::vector<std::vector<int>> limb_dims() const;
  // Three points: the dimensions one hand's point alone gives (side 0 the left hand, 1 the right):
  // its place against the head (3) and its speed (1). A controller out of the headset's view
  // leaves only these unobserved (FollowSession).
  std::array<int, 4> hand_point_dims(int side) const {
    const int place = 3 * side;
    return {place, place + 1, place + 2, block_begin(FeatureBlock::kEffectorSpeed) + side};
  }
  // First dimension and size of a block.
  int block_begin(FeatureBlock block) const;
  int block_size(FeatureBlock block) const;
};

}  // namespace duet
