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
  app.add_flag("!--no-foot-hold", args.foot_hold,
               "Let the blend slide the planted feet after a jump instead of holding them with "
               "leg IK and stepping to the new place (the hold: a third fewer sliding feet, "
               "legs no faster than 8 rad/s beyond the blend's own turn; docs/partner.md)");
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
