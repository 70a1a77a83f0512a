// duet contacts LEADER PARTNER [--fps F] [--scale S] [--padding M] [--json]
// Prints the hand-contact intervals of a captured duet (method.md 5.2), per hand pair.
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "duet/io/motion_file.h"
#include "duet/partner/hand_contacts.h"
#include "motion_options.h"
#include "number_checks.h"

namespace duet::app {

namespace {

struct ContactsArgs {
  std::string leader;
  std::string partner;
  MotionFileOptions motion;
  ContactOptions contacts;
  bool json = false;
};

int run_contacts(const ContactsArgs& args) {
  MotionLoadOptions load_options;
  if (!make_load_options(args.motion, load_options)) return kExitFailure;
  Result<LoadedMotion> leader = load_motion({args.leader}, load_options);
  if (!leader) {
    fmt::print(stderr, "duet contacts: {}\n", leader.error().message);
    return kExitFailure;
  }
  Result<LoadedMotion> partner = load_motion({args.partner}, load_options);
  if (!partner) {
    fmt::print(stderr, "duet contacts: {}\n", partner.error().message);
    return kExitFailure;
  }
  Result<HandContacts> contacts =
      HandContacts::detect(leader.value().clip, leader.value().roles, partner.value().clip,
                           partner.value().roles, args.contacts);
  if (!contacts) {
    fmt::print(stderr, "duet contacts: {}\n", contacts.error().message);
    return kExitFailure;
  }
  const HandContacts& c = contacts.value();
  if (args.json) {
    nlohmann::json doc;
    doc["frames"] = c.frame_count();
    doc["fps"] = c.frame_rate();
    doc["any_contact_fraction"] = c.any_contact_fraction();
    for (int pair = 0; pair < kHandPairCount; ++pair) {
      nlohmann::json entry;
      entry["fraction"] = c.contact_fraction(pair);
      entry["intervals"] = nlohmann::json::array();
      for (const ContactInterval& i : c.intervals(pair)) {
        entry["intervals"].push_back(
            {{"begin", i.begin_frame}, {"end", i.end_frame}, {"begin_s", i.begin_s},
             {"duration_s", i.duration_s}});
      }
      doc["pairs"][std::string(hand_pair_name(pair))] = entry;
    }
    // Names from the files may be any bytes: invalid UTF-8 becomes U+FFFD instead of throwing.
    std::cout << doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return kExitOk;
  }
  fmt::print("{} frames at {:.6g} fps; some hand pair in contact in {:.1f}% of frames\n",
             c.frame_count(), c.frame_rate(), 100.0 * c.any_contact_fraction());
  fmt::print("(pairs are leader hand - partner hand; intervals are frames [begin, end))\n");
  for (int pair = 0; pair < kHandPairCount; ++pair) {
    fmt::print("\n{}: {:.1f}% of frames, {} intervals\n", hand_pair_name(pair),
               100.0 * c.contact_fraction(pair), c.intervals(pair).size());
    for (const ContactInterval& i : c.intervals(pair)) {
      fmt::print("  [{:5d}, {:5d})  {:7.2f} s  for {:5.2f} s\n", i.begin_frame, i.end_frame,
                 i.begin_s, i.duration_s);
    }
  }
  return kExitOk;
}

}  // namespace

Command register_contacts(CLI::App& app) {
  auto args = std::make_shared<ContactsArgs>();
  app.add_option("leader", args->leader, "The leader's motion (BVH)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("partner", args->partner, "The partner's motion (BVH), captured together")
      ->required()
      ->check(CLI::ExistingFile);
  add_motion_file_options(app, args->motion);
  app.add_option("--padding", args->contacts.padding_m,
                 "Metres added around each hand's bounding box")
      ->check(non_negative_check());
  app.add_option("--min-contact", args->contacts.min_contact_s,
                 "Contacts shorter than this (s) are dropped")
      ->check(non_negative_check());
  app.add_option("--min-gap", args->contacts.min_gap_s, "Gaps shorter than this (s) are closed")
      ->check(non_negative_check());
  app.add_flag("--json", args->json, "Print one JSON object");
  return [args] { return run_contacts(*args); };
}

}  // namespace duet::app
