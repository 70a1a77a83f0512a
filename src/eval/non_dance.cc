#include "duet/eval/non_dance.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "duet/live/follow_session.h"
#include "duet/motion/head_hands.h"

namespace duet {

Clip looped_clip(const Clip& clip, double min_duration_s) {
  const int frames = clip.frame_count();
  if (frames < 2 || !(clip.frame_rate() > 0.0) || clip.duration() >= min_duration_s) return clip;
  const int repeats = static_cast<int>(std::ceil(min_duration_s / clip.duration()));
  Clip looped(clip.skeleton_ptr(), clip.frame_rate(), frames * repeats);
  Vec3 walked = clip.translations_ls(frames - 1)[0] - clip.translations_ls(0)[0];
  walked.y() = 0.0;
  for (int r = 0; r < repeats; ++r) {
    for (int f = 0; f < frames; ++f) {
      const int to = r * frames + f;
      std::ranges::copy(clip.translations_ls(f), looped.translations_ls(to).begin());
      std::ranges::copy(clip.rotations_ls(f), looped.rotations_ls(to).begin());
      looped.translations_ls(to)[0] += static_cast<double>(r) * walked;
    }
  }
  return looped;
}

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
