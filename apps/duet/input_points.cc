#include "input_points.h"

#include "duet/motion/head_hands.h"

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

}  // namespace duet::app
