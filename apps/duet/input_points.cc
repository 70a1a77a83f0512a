#include "input_points.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>
#include <vector>

#include "duet/io/motion_argument.h"
#include "duet/live/calibration_advice.h"
#include "duet/live/follow_session.h"
#include "duet/motion/head_hands.h"
#include "number_checks.h"

namespace duet::app {

Result<InputPoints> choose_input_points(const std::string& option, LoadedMotion& motion) {
  InputPoints asked = InputPoints::kFullBody;
  if (!option.empty() && !parse_input_points(option, asked)) {
    return Error{"--input-points: '" + option + "' is neither full nor head,hands"};
  }
  if (is_head_hands_input(motion.roles)) {
    if (!option.empty() && asked == InputPoints::kFullBody) {
      return Error{"--input-points full: " + motion.description +
                   " has only a head and two hands (leave --input-points out, or give "
                   "head,hands)"};
    }
    return InputPoints::kHeadHands;
  }
  if (asked == InputPoints::kFullBody) return InputPoints::kFullBody;
  Result<Clip> points = head_hands_clip(motion.clip, motion.roles);
  if (!points) return Error{"--input-points head,hands: " + motion.description + ": " +
                            points.error().message};
  motion.clip = std::move(points).value();
  motion.roles = head_hands_roles();
  motion.role_detection = RoleDetection{};
  motion.role_detection.roles = motion.roles;
  motion.body = BodyDimensions{};
  motion.metres_per_unit = 1.0;
  return InputPoints::kHeadHands;
}

CLI::Validator input_points_choice(bool with_full) {
  const std::string choices = with_full ? "full or head,hands" : "head,hands";
  return CLI::Validator(
      [with_full, choices](std::string& value) -> std::string {
        if (value == "head,hands" || (with_full && value == "full")) return {};
        return "'" + value + "' is not " + choices +
               " (head,hands is one value: the head and both hands)";
      },
      with_full ? "full|head,hands" : "head,hands");
}

CLI::Option* add_offsets_cm_option(CLI::App& app, const std::string& name, std::vector<double>& cm,
                                   const std::string& help) {
  return app.add_option(name, cm, help)
      ->expected(3)
      ->delimiter(',')
      ->check(number_between(-30.0, 30.0, "cm"));
}

CLI::Option* add_device_offsets_option(CLI::App& app, std::vector<double>& cm,
                                       const std::string& what) {
  return add_offsets_cm_option(
      app, "--device-offsets-cm", cm,
      "Three points: where the devices sit against the head and wrist joints, FORWARD,UP,GRIP in "
      "cm: the headset's eyes FORWARD in front of and UP above the head joint, each controller's "
      "grip GRIP past the wrist along the hand, on the grip's +Y axis (WebXR's grip space). " +
          what);
}

DevicePointOffsets device_offsets_from_cm(const std::vector<double>& cm) {
  if (cm.size() != 3) return DevicePointOffsets{};
  return DevicePointOffsets::from_cm(cm[0], cm[1], cm[2]);
}

CLI::Option* add_head_height_option(CLI::App& app, double& metres) {
  return app
      .add_option("--head-height", metres,
                  "Three points: the height above the floor, in metres, of the input's head "
                  "point with the user standing straight: the headset's for a headset (a height "
                  "calibration; a headset says nothing of the body's size), the head joint's for "
                  "a recording at the joints. Device offsets taken out of the points are taken "
                  "out of it too. Default: learnt as the highest the head has held, which a "
                  "dance that starts low gets wrong until the dancer stands (docs/features.md, "
                  "three points' unit)")
      ->option_text("M")
      ->check(number_between(kHeadPointHeightRangeM[0], kHeadPointHeightRangeM[1], "m"));
}

std::optional<std::string> head_height_note(const Clip& points, const JointRoles& roles,
                                            const DevicePointOffsets& offsets) {
  // Within 5 % the learnt size does no harm (docs/evaluation.md, "A head height from a
  // calibration": 3 % off costs nothing measurable).
  constexpr double kRiseFraction = 0.05;
  const int first_second = static_cast<int>(std::ceil(points.frame_rate()));
  const double first = highest_head_m(points, roles, first_second);
  const double highest = highest_head_m(points, roles);
  if (!(first > 0.0) || highest <= (1.0 + kRiseFraction) * first) return std::nullopt;
  const double head_point = highest + offsets.eyes_m.y();
  return fmt::format(
      "the head was at most {:.2f} m high in the first second and {:.2f} m later: the follower "
      "learns the body's size from the highest the head has held, so it took the dancer as "
      "{:.0f} % smaller until they stood. --head-height {:.2f} (the head's height standing) "
      "gives the size from the first frame",
      first + offsets.eyes_m.y(), head_point, 100.0 * (1.0 - first / highest), head_point);
}

std::optional<std::string> calibration_note(std::span<const FollowResult> results,
                                            double frame_rate_hz) {
  CalibrationAdvice advice;
  for (const FollowResult& r : results) advice.observe(r, 1.0 / frame_rate_hz);
  const std::optional<float> offset = advice.other_body_offset();
  if (!offset) return std::nullopt;
  return fmt::format(
      "the hands were held elsewhere against the head than the library's dancers hold them (a "
      "learnt offset of {:.3f}; the library's own body under 0.02): the follower learns it as "
      "you dance, and places you less surely until it has (another body's three points: 7-17 "
      "points fewer frames within 100 ms, nearly all in the first 5 s). --calibration POSE.csv, "
      "a second of you standing straight with both arms held straight forward, gives it from the "
      "first frame",
      *offset);
}

Status check_head_height_applies(double metres, InputPoints points) {
  if (metres > 0.0 && points != InputPoints::kHeadHands) {
    return Error{
        "--head-height applies to three points (a headset's recording, --input-points "
        "head,hands or --source xr); a full body's size is its skeleton's"};
  }
  return Ok{};
}

CLI::Option* add_calibration_option(CLI::App& app, std::string& path) {
  return app
      .add_option("--calibration", path,
                  "Three points: a recording of the user standing straight with both arms held "
                  "straight forward, level with the shoulders, for a second (a three-point CSV "
                  "taken like the input, or any motion file). Gives the body's size (the head's "
                  "height, unless --head-height says) and where the body holds its hands, so "
                  "that another body, or another rig, is followed as well as the library's own "
                  "(docs/features.md, \"A body calibration\")")
      ->option_text("FILE");
}

Result<BodyCalibration> read_body_calibration(const std::string& path,
                                              const std::vector<double>& device_offsets_cm) {
  Result<std::vector<std::string>> files = split_motion_argument(path);
  if (!files) return Error{"--calibration: " + files.error().message};
  Result<LoadedMotion> motion = load_motion(files.value(), MotionLoadOptions{});
  if (!motion) return Error{"--calibration: " + motion.error().message};
  LoadedMotion& pose = motion.value();
  if (is_head_hands_input(pose.roles)) {
    if (Status s = take_out_device_offsets(device_offsets_cm, pose); !s) return s.error();
  } else {
    Result<Clip> points = head_hands_clip(pose.clip, pose.roles);
    if (!points) return Error{"--calibration: " + path + ": " + points.error().message};
    pose.clip = std::move(points).value();
  }
  BodyCalibration calibration;
  Result<ArmsForward> arms = arms_forward_of_points(pose.clip);
  if (!arms) return Error{"--calibration: " + path + ": " + arms.error().message};
  calibration.arms_forward = arms.value();
  calibration.head_height_m = median_head_height(pose.clip);  // the clip is in metres
  const auto [lowest, highest] = FollowSession::kHeadHeightRangeM;
  if (!(calibration.head_height_m >= lowest && calibration.head_height_m <= highest)) {
    return Error{fmt::format(
        "--calibration: {}: the head is {:.2f} m high, not {:g}-{:g} m: no one standing straight",
        path, calibration.head_height_m, lowest, highest)};
  }
  return calibration;
}

Status check_calibration_applies(const std::string& path, InputPoints points) {
  if (!path.empty() && points != InputPoints::kHeadHands) {
    return Error{
        "--calibration applies to three points (a headset's recording, --input-points "
        "head,hands or --source xr); a full body's proportions are its skeleton's"};
  }
  return Ok{};
}

Status take_out_device_offsets(const std::vector<double>& cm, LoadedMotion& motion) {
  if (cm.empty()) return Ok{};
  if (!is_head_hands_input(motion.roles) || motion.clip.joint_count() != kHeadHandsJointCount) {
    return Error{"--device-offsets-cm: " + motion.description +
                 " is no recording of three devices (a full body, and three points made from "
                 "one, are at the joints already)"};
  }
  DevicePointOffsets offsets = device_offsets_from_cm(cm);
  // In the file's units.
  offsets.eyes_m /= motion.metres_per_unit;
  offsets.grip_m /= motion.metres_per_unit;
  device_points_to_joints(offsets, motion.clip);
  return Ok{};
}

}  // namespace duet::app
