#include "duet/partner/hand_contacts.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

constexpr std::array<std::string_view, kHandPairCount> kPairNames = {"left-left", "left-right",
                                                                     "right-left", "right-right"};

Role wrist_role(Side side) { return side == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist; }

// The joints of the hand rooted at `hand`: the hand itself and everything below it.
std::vector<int> hand_joints(const Skeleton& skeleton, int hand) {
  std::vector<bool> below(skeleton.joints.size(), false);
  std::vector<int> joints;
  for (int j = hand; j < skeleton.joint_count(); ++j) {
    const int parent = skeleton.joints[static_cast<std::size_t>(j)].parent;
    if (j == hand || (parent >= 0 && below[static_cast<std::size_t>(parent)])) {
      below[static_cast<std::size_t>(j)] = true;
      joints.push_back(j);
    }
  }
  return joints;
}

struct Box {
  Vec3 lo;
  Vec3 hi;
};

Box bounds(const std::vector<Vec3>& positions, const std::vector<int>& joints) {
  Box box{positions[static_cast<std::size_t>(joints[0])],
          positions[static_cast<std::size_t>(joints[0])]};
  for (const int j : joints) {
    box.lo = box.lo.cwiseMin(positions[static_cast<std::size_t>(j)]);
    box.hi = box.hi.cwiseMax(positions[static_cast<std::size_t>(j)]);
  }
  return box;
}

// Largest per-axis separation of two boxes; 0 when they overlap.
double separation(const Box& p, const Box& q) {
  const Vec3 gap = (q.lo - p.hi).cwiseMax(p.lo - q.hi).cwiseMax(0.0);
  return gap.maxCoeff();
}

int frames_for(double seconds, double frame_rate) {
  if (!(seconds > 0.0)) return 0;
  return static_cast<int>(std::ceil(seconds * frame_rate - 1e-9));
}

Status check_wrists(const Clip& clip, const JointRoles& roles, const char* which) {
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const int j = roles[wrist_role(side)];
    if (j < 0 || j >= clip.joint_count()) {
      return Error{std::string("hand contacts: the ") + which + " skeleton has no " +
                   std::string(role_name(wrist_role(side))) + " joint (role index " +
                   std::to_string(j) + ")"};
    }
  }
  return Ok{};
}

}  // namespace

std::string_view hand_pair_name(int pair) {
  assert(pair >= 0 && pair < kHandPairCount);
  return kPairNames[static_cast<std::size_t>(pair)];
}

void debounce(std::vector<bool>& track, int min_gap_frames, int min_contact_frames) {
  const int n = static_cast<int>(track.size());
  const auto at = [&](int i) { return track[static_cast<std::size_t>(i)]; };
  const auto set = [&](int begin, int end, bool value) {
    for (int i = begin; i < end; ++i) track[static_cast<std::size_t>(i)] = value;
  };
  // Fill short gaps that lie between two contacts (not before the first or after the last).
  for (int i = 0; i < n;) {
    if (at(i)) {
      ++i;
      continue;
    }
    int end = i;
    while (end < n && !at(end)) ++end;
    if (i > 0 && end < n && end - i < min_gap_frames) set(i, end, true);
    i = end;
  }
  // Then drop short contacts.
  for (int i = 0; i < n;) {
    if (!at(i)) {
      ++i;
      continue;
    }
    int end = i;
    while (end < n && at(end)) ++end;
    if (end - i < min_contact_frames) set(i, end, false);
    i = end;
  }
}

Result<HandContacts> HandContacts::detect(const Clip& template_clip,
                                          const JointRoles& template_roles,
                                          const Clip& response_clip,
                                          const JointRoles& response_roles,
                                          const ContactOptions& options) {
  if (template_clip.frame_count() != response_clip.frame_count()) {
    return Error{"hand contacts: the template has " + std::to_string(template_clip.frame_count()) +
                 " frames, the response " + std::to_string(response_clip.frame_count()) +
                 " (a duet needs the same count)"};
  }
  if (!(template_clip.frame_rate() > 0.0) ||
      std::abs(template_clip.frame_rate() - response_clip.frame_rate()) >
          1e-9 * template_clip.frame_rate()) {
    return Error{"hand contacts: the template runs at " +
                 std::to_string(template_clip.frame_rate()) + " fps, the response at " +
                 std::to_string(response_clip.frame_rate()) + " fps (a duet needs one rate)"};
  }
  if (!(options.padding_m >= 0.0) || !std::isfinite(options.padding_m) ||
      !(options.min_gap_s >= 0.0) || !std::isfinite(options.min_gap_s) ||
      !(options.min_contact_s >= 0.0) || !std::isfinite(options.min_contact_s)) {
    return Error{"hand contacts: padding and minimum durations must be finite and >= 0"};
  }
  if (Status s = check_wrists(template_clip, template_roles, "template"); !s) return s.error();
  if (Status s = check_wrists(response_clip, response_roles, "response"); !s) return s.error();

  HandContacts contacts;
  const int frames = template_clip.frame_count();
  contacts.frame_count_ = frames;
  contacts.frame_rate_ = template_clip.frame_rate();
  contacts.options_ = options;
  contacts.mask_.assign(static_cast<std::size_t>(frames), 0);
  contacts.raw_mask_.assign(static_cast<std::size_t>(frames), 0);
  contacts.box_gap_.assign(static_cast<std::size_t>(frames) * kHandPairCount, 0.0f);
  contacts.offset_ls_.assign(static_cast<std::size_t>(frames) * kHandPairCount, Vec3::Zero());
  contacts.template_wrist_rotations_ws_.assign(static_cast<std::size_t>(frames) * kSideCount,
                                               Quat::Identity());

  const Clip* clips[2] = {&template_clip, &response_clip};
  const JointRoles* roles[2] = {&template_roles, &response_roles};
  std::array<std::array<std::vector<int>, kSideCount>, 2> hands;
  std::array<std::vector<Vec3>, 2> positions;
  std::array<std::vector<Quat>, 2> rotations;
  for (int c = 0; c < 2; ++c) {
    for (const Side side : {Side::kLeft, Side::kRight}) {
      hands[c][static_cast<std::size_t>(side)] =
          hand_joints(clips[c]->skeleton(), (*roles[c])[wrist_role(side)]);
    }
    positions[c].resize(static_cast<std::size_t>(clips[c]->joint_count()));
    rotations[c].resize(static_cast<std::size_t>(clips[c]->joint_count()));
  }

  const double touch = 2.0 * options.padding_m;
  std::array<std::vector<bool>, kHandPairCount> tracks;
  for (auto& track : tracks) track.assign(static_cast<std::size_t>(frames), false);
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < 2; ++c) {
      forward_kinematics(clips[c]->skeleton(), clips[c]->translations_ls(f),
                         clips[c]->rotations_ls(f), positions[c], rotations[c]);
    }
    for (const Side side : {Side::kLeft, Side::kRight}) {
      const auto s = static_cast<std::size_t>(side);
      contacts.template_wrist_rotations_ws_[static_cast<std::size_t>(f) * kSideCount + s] =
          rotations[0][static_cast<std::size_t>(hands[0][s][0])];
    }
    std::uint8_t raw = 0;
    for (int p = 0; p < kHandPairCount; ++p) {
      const auto ts = static_cast<std::size_t>(template_side(p));
      const auto rs = static_cast<std::size_t>(response_side(p));
      const double gap =
          separation(bounds(positions[0], hands[0][ts]), bounds(positions[1], hands[1][rs]));
      const std::size_t k = contacts.index(f, p);
      contacts.box_gap_[k] = static_cast<float>(gap);
      const auto tw = static_cast<std::size_t>(hands[0][ts][0]);
      const auto rw = static_cast<std::size_t>(hands[1][rs][0]);
      contacts.offset_ls_[k] = rotations[0][tw].conjugate() * (positions[1][rw] - positions[0][tw]);
      if (gap <= touch) {
        raw = static_cast<std::uint8_t>(raw | (1u << p));
        tracks[static_cast<std::size_t>(p)][static_cast<std::size_t>(f)] = true;
      }
    }
    contacts.raw_mask_[static_cast<std::size_t>(f)] = raw;
  }

  const int min_gap = frames_for(options.min_gap_s, contacts.frame_rate_);
  const int min_contact = frames_for(options.min_contact_s, contacts.frame_rate_);
  for (int p = 0; p < kHandPairCount; ++p) {
    std::vector<bool>& track = tracks[static_cast<std::size_t>(p)];
    debounce(track, min_gap, min_contact);
    auto& intervals = contacts.intervals_[static_cast<std::size_t>(p)];
    for (int f = 0; f < frames;) {
      if (!track[static_cast<std::size_t>(f)]) {
        ++f;
        continue;
      }
      int end = f;
      while (end < frames && track[static_cast<std::size_t>(end)]) {
        auto& m = contacts.mask_[static_cast<std::size_t>(end)];
        m = static_cast<std::uint8_t>(m | (1u << p));
        ++end;
      }
      intervals.push_back({f, end, f / contacts.frame_rate_, (end - f) / contacts.frame_rate_});
      f = end;
    }
  }
  return contacts;
}

std::size_t HandContacts::index(int frame, int pair) const noexcept {
  assert(frame >= 0 && frame < frame_count_ && pair >= 0 && pair < kHandPairCount);
  return static_cast<std::size_t>(frame) * kHandPairCount + static_cast<std::size_t>(pair);
}

bool HandContacts::in_contact(int frame, int pair) const noexcept {
  assert(frame >= 0 && frame < frame_count_ && pair >= 0 && pair < kHandPairCount);
  return (mask_[static_cast<std::size_t>(frame)] >> pair) & 1u;
}

std::uint8_t HandContacts::mask(int frame) const noexcept {
  assert(frame >= 0 && frame < frame_count_);
  return mask_[static_cast<std::size_t>(frame)];
}

bool HandContacts::raw_contact(int frame, int pair) const noexcept {
  assert(frame >= 0 && frame < frame_count_ && pair >= 0 && pair < kHandPairCount);
  return (raw_mask_[static_cast<std::size_t>(frame)] >> pair) & 1u;
}

double HandContacts::box_gap(int frame, int pair) const noexcept {
  return box_gap_[index(frame, pair)];
}

const Vec3& HandContacts::offset_ls(int frame, int pair) const noexcept {
  return offset_ls_[index(frame, pair)];
}

Vec3 HandContacts::offset_ls_at(double frame, int pair) const noexcept {
  const auto [f0, f1, w] = bracket_frame(frame, frame_count());
  return (1.0 - w) * offset_ls(f0, pair) + w * offset_ls(f1, pair);
}

Quat HandContacts::template_wrist_rotation_at(double frame, Side side) const noexcept {
  const auto [f0, f1, w] = bracket_frame(frame, frame_count());
  const auto s = static_cast<std::size_t>(side);
  const Quat& q0 = template_wrist_rotations_ws_[static_cast<std::size_t>(f0) * kSideCount + s];
  const Quat& q1 = template_wrist_rotations_ws_[static_cast<std::size_t>(f1) * kSideCount + s];
  return q0.slerp(w, q1).normalized();
}

std::span<const ContactInterval> HandContacts::intervals(int pair) const noexcept {
  assert(pair >= 0 && pair < kHandPairCount);
  return intervals_[static_cast<std::size_t>(pair)];
}

double HandContacts::contact_fraction(int pair) const noexcept {
  if (frame_count_ == 0) return 0.0;
  int frames = 0;
  for (const ContactInterval& i : intervals(pair)) frames += i.end_frame - i.begin_frame;
  return static_cast<double>(frames) / frame_count_;
}

double HandContacts::any_contact_fraction() const noexcept {
  if (frame_count_ == 0) return 0.0;
  const auto n = std::count_if(mask_.begin(), mask_.end(), [](std::uint8_t m) { return m != 0; });
  return static_cast<double>(n) / frame_count_;
}

}  // namespace duet
