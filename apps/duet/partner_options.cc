#include "partner_options.h"

namespace duet::app {

void add_partner_options(CLI::App& app, PartnerArgs& args) {
  app.add_flag("--no-align", args.no_align,
               "Do not place the partner relative to the user (keep the capture's place)");
  app.add_flag("--no-contact", args.no_contact, "No hand-contact IK");
  app.add_flag("--no-smooth", args.no_smooth,
               "No smoothing: per-joint rotations, the user's heading, the contact IK target, "
               "the tempo playhead (the raw whole-frame estimate is shown)");
  app.add_flag("--no-footlock", args.no_footlock,
               "Do not hold the feet the captured partner has planted");
  app.add_flag("--no-blend", args.no_blend, "Cut instead of blending when the follower jumps");
  app.add_flag("--foot-hold,!--no-foot-hold", args.foot_hold,
               "After a jump, hold the planted feet with leg IK while the blend carries the "
               "partner and step to the new place (on by default: sliding feet after jumps 186 "
               "-> 111 of 188 measured, legs no faster than 8 rad/s beyond the blend's own "
               "turn); --no-foot-hold lets the blend slide them (docs/partner.md)");
  app.add_option("--ik-target", args.ik_target,
                 "Where a held hand goes: offset (the captured grip relative to the user's hand, "
                 "default) or wrist (the user's wrist, as in the paper)")
      ->check(CLI::IsMember({"offset", "wrist"}));
}

PartnerParams make_partner_params(const PartnerArgs& args) {
  PartnerParams params;
  params.align = !args.no_align;
  params.contact = !args.no_contact;
  params.smooth = !args.no_smooth;
  params.foot_lock = !args.no_footlock;
  params.blend = !args.no_blend;
  params.foot_hold.enabled = args.foot_hold;
  parse_ik_target(args.ik_target, params.ik_target);
  return params;
}

}  // namespace duet::app
