// Hand contacts of a captured duet (method.md 5.2, paper 5.2), detected offline.
//
// Per frame and per hand pair (template left/right x response left/right), the hands touch when
// their padded axis-aligned bounding boxes overlap (a simple collision test as in Peinado et al.).
// A hand's box spans the hand joint and every joint below it (fingers, End Sites), grown by
// `padding_m` on every side. Then, per pair, short gaps inside a contact are filled and short
// contacts are dropped (debouncing). For every frame the captured wrist-to-wrist offset is kept,
// expressed in the template hand's frame: at run time the partner's wrist target is that offset
// carried by the user's hand.
//
// "Template" is the dancer the user dances; "response" is the virtual partner. To list the
// contacts of a captured pair as leader x partner, pass the leader as the template.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

enum class Side : int { kLeft = 0, kRight = 1 };
constexpr int kSideCount = 2;

// Hand pairs are indexed 2 * template side + response side.
constexpr int kHandPairCount = 4;
constexpr int hand_pair(Side template_hand, Side response_hand) {
  return 2 * static_cast<int>(template_hand) + static_cast<int>(response_hand);
}
constexpr Side template_side(int pair) { return static_cast<Side>(pair / 2); }
constexpr Side response_side(int pair) { return static_cast<Side>(pair % 2); }
// "left-left", "left-right", "right-left", "right-right": template hand first.
std::string_view hand_pair_name(int pair);

struct ContactOptions {
  // Growth of each hand's box on every side, metres: two hands touch when their boxes are at most
  // 2 * padding_m apart along every axis. Large by default because the CMU salsa takes share one
  // generic skeleton, so hands that hold each other are captured 0.1-0.3 m apart (measured on
  // 60_01 + 61_01, see docs/partner.md).
  double padding_m = 0.1;
  // Gaps shorter than this between two contacts are filled (seconds).
  double min_gap_s = 0.2;
  // Contacts shorter than this (after filling gaps) are dropped (seconds).
  double min_contact_s = 0.2;
};

// One contact: frames [begin_frame, end_frame).
struct ContactInterval {
  int begin_frame = 0;
  int end_frame = 0;
  double begin_s = 0.0;
  double duration_s = 0.0;
};

class HandContacts {
 public:
  HandContacts() = default;

  // The clips must have the same frame count and rate; the roles must name their hands (wrist
  // roles). Bad input returns an error that says what is wrong.
  static Result<HandContacts> detect(const Clip& template_clip, const JointRoles& template_roles,
                                     const Clip& response_clip, const JointRoles& response_roles,
                                     const ContactOptions& options = {});

  int frame_count() const noexcept { return frame_count_; }
  double frame_rate() const noexcept { return frame_rate_; }
  const ContactOptions& options() const noexcept { return options_; }

  // After debouncing. frame in [0, frame_count()), pair in [0, kHandPairCount).
  bool in_contact(int frame, int pair) const noexcept;
  // Bit p set when pair p is in contact at `frame` (after debouncing).
  std::uint8_t mask(int frame) const noexcept;
  // Before debouncing: the boxes overlap at this frame.
  bool raw_contact(int frame, int pair) const noexcept;
  // Separation of the two unpadded boxes: the largest per-axis gap in metres (0 when they
  // overlap). The hands touch (raw) when box_gap <= 2 * padding_m.
  double box_gap(int frame, int pair) const noexcept;
  // Captured response wrist position minus template wrist position, expressed in the template
  // hand joint's frame (metres). Stored for every frame, in contact or not.
  const Vec3& offset_ls(int frame, int pair) const noexcept;
  // The same at a real frame (clamped to the clip): lerp between the two nearest frames.
  Vec3 offset_ls_at(double frame, int pair) const noexcept;
  // The template's hand joint rotation in the capture's world at a real frame (clamped; slerp):
  // what the user's sensed hand rotation is compared with (steady_difference.h).
  Quat template_wrist_rotation_at(double frame, Side side) const noexcept;

  std::span<const ContactInterval> intervals(int pair) const noexcept;
  // Fraction of frames in which pair is in contact (after debouncing), in [0, 1].
  double contact_fraction(int pair) const noexcept;
  // Fraction of frames in which any pair is in contact.
  double any_contact_fraction() const noexcept;

 private:
  std::size_t index(int frame, int pair) const noexcept;

  int frame_count_ = 0;
  double frame_rate_ = 0.0;
  ContactOptions options_;
  std::vector<std::uint8_t> mask_;      // per frame, debounced
  std::vector<std::uint8_t> raw_mask_;  // per frame
  std::vector<float> box_gap_;          // frame * kHandPairCount + pair
  std::vector<Vec3> offset_ls_;         // frame * kHandPairCount + pair
  std::vector<Quat> template_wrist_rotations_ws_;  // frame * kSideCount + side
  std::array<std::vector<ContactInterval>, kHandPairCount> intervals_;
};

// Debouncing on one boolean track: fills runs of false shorter than min_gap_frames that lie
// between two runs of true, then clears runs of true shorter than min_contact_frames. Exposed for
// tests and for other per-frame labels.
void debounce(std::vector<bool>& track, int min_gap_frames, int min_contact_frames);

}  // namespace duet
