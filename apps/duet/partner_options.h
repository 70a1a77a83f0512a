// Command-line switches for the partner corrections (method.md 5): --no-align, --no-contact,
// --no-smooth, --no-footlock, --no-blend, --no-foot-hold, --ik-target.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "duet/partner/partner_synthesis.h"

namespace duet::app {

struct PartnerArgs {
  bool no_align = false;
  bool no_contact = false;
  bool no_smooth = false;
  bool no_footlock = false;
  bool no_blend = false;
  bool foot_hold = true;
  std::string ik_target = "offset";
};

void add_partner_options(CLI::App& app, PartnerArgs& args);
PartnerParams make_partner_params(const PartnerArgs& args);

}  // namespace duet::app
