#include "duet/eval/non_dance.h"

#include <optional>
#include <utility>

#include "duet/live/follow_session.h"
#include "duet/motion/head_hands.h"

namespace duet {

Result<NonDanceResult> follow_non_dance(const DuetLibrary& library, const LoadedMotion& input,
                                        std::string name, std::unique_ptr<Tracker> tracker) {
  // A three-point library meets what a headset would give: the clip's head and hands, as every
  // three-point input is made (duet follow --input-points head,hands, the eval's cases).
  const Clip* clip = &input.clip;
  const JointRoles* roles = &input.roles;
  std::optional<Clip> points;
  const JointRoles points_roles = head_hands_roles();
  if (library.options().features.input_points == InputPoints::kHeadHands &&
      !is_head_hands_input(input.roles)) {
    Result<Clip> made = head_hands_clip(input.clip, input.roles);
    if (!made) return Error{name + ": " + made.error().message};
    points = std::move(made).value();
    clip = &*points;
    roles = &points_roles;
  }
  Result<FollowSession> session =
      FollowSession::create(library, clip->skeleton_ptr(), *roles, std::move(tracker));
  if (!session) return Error{name + ": " + session.error().message};
  NonDanceResult result;
  result.name = std::move(name);
  const double rate = clip->frame_rate();
  for (int f = 0; f < clip->frame_count(); ++f) {
    const FollowResult r =
        session.value().step(clip->translations_ls(f), clip->rotations_ls(f), f / rate);
    ++result.frames;
    result.lost += r.lost ? 1 : 0;
  }
  return result;
}

}  // namespace duet
