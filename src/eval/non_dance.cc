#include "duet/eval/non_dance.h"

#include <utility>

#include "duet/live/follow_session.h"

namespace duet {

Result<NonDanceResult> follow_non_dance(const DuetLibrary& library, const LoadedMotion& input,
                                        std::string name, std::unique_ptr<Tracker> tracker) {
  Result<FollowSession> session =
      FollowSession::create(library, input.clip.skeleton_ptr(), input.roles, std::move(tracker));
  if (!session) return Error{name + ": " + session.error().message};
  NonDanceResult result;
  result.name = std::move(name);
  const double rate = input.clip.frame_rate();
  for (int f = 0; f < input.clip.frame_count(); ++f) {
    const FollowResult r =
        session.value().step(input.clip.translations_ls(f), input.clip.rotations_ls(f), f / rate);
    ++result.frames;
    result.lost += r.lost ? 1 : 0;
  }
  return result;
}

}  // namespace duet
