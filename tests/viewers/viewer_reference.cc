// Reference world positions for the viewer checks (tests/viewers/check_bvh_in_viewers.sh), computed
// with duet's own BVH reader and forward kinematics.
//
//   viewer_reference --user USER.bvh --partner PARTNER.bvh --input INPUT.bvh --trace TRACE.csv
//                    --leader LEADER.bvh --follower FOLLOWER.bvh --contacts CONTACTS.json
//                    --out OUT.json [--every N]
//
// USER.bvh and PARTNER.bvh are what `duet follow -o PARTNER.bvh --user-output USER.bvh` wrote (in
// metres); INPUT.bvh is the performance that was followed (in its own units, detected from the
// skeleton convention as `duet follow` does). The user's reference positions come from INPUT.bvh,
// not from USER.bvh, so a unit or frame error in the written user file shows; USER.bvh read back
// must agree with them (checked here). The partner's reference is PARTNER.bvh read back.
// LEADER.bvh and FOLLOWER.bvh are the one captured duet that was followed (the user dances the
// leader), CONTACTS.json its `duet contacts --json`.
//
// Checked frames: every N-th frame (default 10), the last frame, and up to 24 "contact
// frames": frames where, by the follower's trace and the captured contacts of the take
// (`duet contacts --json` of the one pair followed), a hand pair has been in contact for the
// last 0.3 s and the follower has not jumped for 1 s (so the contact IK holds the partner's
// hand at full weight and nothing is blending).
//
// OUT.json: {"fps", "frames", "frames_checked": [f...], "joints": {"user": [...], "partner":
// [...]}, "user": [[[x,y,z] per joint] per checked frame], "partner": likewise, "roles": {"user":
// {"hips": name, "left_wrist": ..., ...}, "partner": ...}, "contacts": [{"frame", "pair",
// "user_joint", "partner_joint", "template_frame", "captured_distance_m"}],
// "captured_hips_distance_m": [per checked frame], "user_file_vs_input_max_m"};
// captured_distance_m is how far apart the two wrist joints were in the capture at the follower's
// template frame (the contact IK reproduces that grip), captured_hips_distance_m the horizontal
// distance of the two hips joints there (the alignment reproduces the couple's spacing). Lengths in
// metres, BVH axes (y up).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "duet/io/motion_file.h"
#include "duet/motion/forward_kinematics.h"

namespace {

using duet::Clip;
using duet::LoadedMotion;
using duet::Vec3;
using nlohmann::json;

struct TraceRow {
  int take = -1;
  int template_frame = -1;
  bool jumped = false;
  bool lost = false;
};

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "viewer_reference: " << message << "\n";
  std::exit(1);
}

LoadedMotion load(const std::string& path, std::optional<double> metres_per_unit) {
  duet::MotionLoadOptions options;
  options.metres_per_unit = metres_per_unit;
  duet::Result<LoadedMotion> loaded = duet::load_motion({path}, options);
  if (!loaded) fail(loaded.error().message);
  return std::move(loaded).value();
}

std::vector<TraceRow> read_trace(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path + ": cannot open");
  std::string line;
  std::getline(in, line);  // header: frame,time_s,take,template_frame,confidence,jumped,lost,...
  std::vector<TraceRow> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (cells.size() < 7) fail(path + ": expected at least 7 columns in '" + line + "'");
    TraceRow row;
    row.take = std::stoi(cells[2]);
    row.template_frame = std::stoi(cells[3]);
    row.jumped = cells[5] == "1";
    row.lost = cells[6] == "1";
    rows.push_back(row);
  }
  return rows;
}

json roles_json(const LoadedMotion& m) {
  json roles;
  for (int r = 0; r < duet::kRoleCount; ++r) {
    const int joint = m.roles.joints[static_cast<std::size_t>(r)];
    roles[std::string(duet::role_name(static_cast<duet::Role>(r)))] =
        m.clip.skeleton().joints[static_cast<std::size_t>(joint)].name;
  }
  return roles;
}

std::vector<int> animated_joints(const Clip& clip) {
  std::vector<int> joints;
  for (int j = 0; j < clip.joint_count(); ++j) {
    if (!clip.skeleton().joints[static_cast<std::size_t>(j)].end_site) joints.push_back(j);
  }
  return joints;
}

json names_json(const Clip& clip, const std::vector<int>& joints) {
  json names = json::array();
  for (int j : joints) names.push_back(clip.skeleton().joints[static_cast<std::size_t>(j)].name);
  return names;
}

double round_um(double v) { return std::round(v * 1e6) / 1e6; }

json positions_json(const std::vector<Vec3>& ws, int joint_count, const std::vector<int>& joints,
                    const std::vector<int>& frames) {
  json out = json::array();
  for (int f : frames) {
    json row = json::array();
    for (int j : joints) {
      const Vec3& p = ws[static_cast<std::size_t>(f * joint_count + j)];
      row.push_back({round_um(p.x()), round_um(p.y()), round_um(p.z())});
    }
    out.push_back(row);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  // Named options only, so no input file can be taken for the output.
  std::map<std::string, std::string> opt;
  const std::vector<std::string> names = {"--user",     "--partner", "--input",
                                          "--trace",    "--leader",  "--follower",
                                          "--contacts", "--out",     "--every"};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::ranges::find(names, argv[i]) == names.end()) {
      fail(std::string("unknown option ") + argv[i]);
    }
    opt[argv[i]] = argv[i + 1];
  }
  for (const std::string& name : names) {
    if (argc % 2 == 0 || (name != "--every" && !opt.contains(name))) {
      std::cerr << "usage: viewer_reference --user USER.bvh --partner PARTNER.bvh --input "
                   "INPUT.bvh --trace TRACE.csv --leader LEADER.bvh --follower FOLLOWER.bvh "
                   "--contacts CONTACTS.json --out OUT.json [--every N]\n";
      return 2;
    }
  }
  const std::string out_path = opt["--out"];
  if (!out_path.ends_with(".json")) fail("--out " + out_path + ": the output must be a .json file");
  const int every = opt.contains("--every") ? std::max(1, std::stoi(opt["--every"])) : 10;
  // duet writes in the source files' units; read back like any other file (its convention's).
  const LoadedMotion user_file = load(opt["--user"], std::nullopt);
  const LoadedMotion partner = load(opt["--partner"], std::nullopt);
  const LoadedMotion input = load(opt["--input"], std::nullopt);
  const std::vector<TraceRow> trace = read_trace(opt["--trace"]);
  const LoadedMotion leader = load(opt["--leader"], std::nullopt);
  const LoadedMotion follower = load(opt["--follower"], std::nullopt);
  json contacts_doc;
  {
    std::ifstream in(opt["--contacts"]);
    if (!in) fail(opt["--contacts"] + ": cannot open");
    contacts_doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (contacts_doc.is_discarded()) fail(opt["--contacts"] + ": not JSON");
  }
  if (leader.clip.frame_count() != follower.clip.frame_count()) fail("the duet's takes differ");

  const int frames = input.clip.frame_count();
  const double fps = input.clip.frame_rate();
  if (user_file.clip.frame_count() != frames || partner.clip.frame_count() != frames ||
      static_cast<int>(trace.size()) != frames) {
    fail("frame counts differ: input " + std::to_string(frames) + ", user file " +
         std::to_string(user_file.clip.frame_count()) + ", partner file " +
         std::to_string(partner.clip.frame_count()) + ", trace " + std::to_string(trace.size()));
  }
  if (user_file.clip.joint_count() != input.clip.joint_count()) fail("user skeleton differs");

  const std::vector<Vec3> input_ws = duet::world_positions(input.clip);
  const std::vector<Vec3> user_ws = duet::world_positions(user_file.clip);
  const std::vector<Vec3> partner_ws = duet::world_positions(partner.clip);
  double user_vs_input = 0.0;
  for (std::size_t i = 0; i < input_ws.size(); ++i) {
    user_vs_input = std::max(user_vs_input, (input_ws[i] - user_ws[i]).norm());
  }
  if (!(user_vs_input < 1e-4)) {
    fail("the user file read back is " + std::to_string(user_vs_input) +
         " m away from the input performance");
  }

  // Contact frames: the follower has stayed inside one captured contact interval of a hand pair
  // for the last 0.3 s (the IK weight has faded in: 0.25 s), and has neither jumped nor been lost
  // for the last 1 s (after a jump the partner's pose, and the IK target, blend for a while).
  const int hold = static_cast<int>(std::ceil(0.3 * fps));
  const int settle = static_cast<int>(std::ceil(1.0 * fps));
  std::vector<int> last_jump(static_cast<std::size_t>(frames), -settle - 1);
  for (int f = 0; f < frames; ++f) {
    const TraceRow& row = trace[static_cast<std::size_t>(f)];
    last_jump[static_cast<std::size_t>(f)] =
        row.jumped || row.lost ? f
                               : (f > 0 ? last_jump[static_cast<std::size_t>(f - 1)] : -settle - 1);
  }
  struct Contact {
    int frame;
    std::string pair;
    int interval;
  };
  std::vector<Contact> candidates;
  const json& pairs = contacts_doc.at("pairs");
  for (auto it = pairs.begin(); it != pairs.end(); ++it) {
    const std::string& pair = it.key();
    const json& intervals = it.value().at("intervals");
    for (int f = hold; f < frames; ++f) {
      int interval = -1;
      bool held = f - last_jump[static_cast<std::size_t>(f)] > settle;
      for (int g = f - hold; g <= f && held; ++g) {
        const TraceRow& row = trace[static_cast<std::size_t>(g)];
        int found = -1;
        for (std::size_t k = 0; k < intervals.size(); ++k) {
          if (row.template_frame >= intervals[k].at("begin").get<int>() &&
              row.template_frame < intervals[k].at("end").get<int>()) {
            found = static_cast<int>(k);
          }
        }
        held = row.take == 0 && found >= 0 && (interval < 0 || found == interval);
        interval = found;
      }
      if (held) candidates.push_back({f, pair, interval});
    }
  }
  std::vector<Contact> contacts;
  const std::size_t max_contacts = 24;
  for (std::size_t i = 0; i < std::min(max_contacts, candidates.size()); ++i) {
    contacts.push_back(
        candidates[i * candidates.size() / std::min(max_contacts, candidates.size())]);
  }

  std::vector<int> checked;
  for (int f = 0; f < frames; f += every) checked.push_back(f);
  checked.push_back(frames - 1);
  for (const Contact& c : contacts) checked.push_back(c.frame);
  std::ranges::sort(checked);
  checked.erase(std::unique(checked.begin(), checked.end()), checked.end());

  const json user_roles = roles_json(input);
  const json partner_roles = roles_json(partner);
  const std::vector<Vec3> leader_ws = duet::world_positions(leader.clip);
  const std::vector<Vec3> follower_ws = duet::world_positions(follower.clip);
  json contacts_json = json::array();
  for (const Contact& c : contacts) {
    // "left-right" = the leader's (the user's) left hand with the partner's right hand.
    const std::string user_side = c.pair.substr(0, c.pair.find('-'));
    const std::string partner_side = c.pair.substr(c.pair.find('-') + 1);
    const duet::Role user_role =
        user_side == "left" ? duet::Role::kLeftWrist : duet::Role::kRightWrist;
    const duet::Role partner_role =
        partner_side == "left" ? duet::Role::kLeftWrist : duet::Role::kRightWrist;
    const int t = trace[static_cast<std::size_t>(c.frame)].template_frame;
    const Vec3& lw = leader_ws[static_cast<std::size_t>(t * leader.clip.joint_count() +
                                                        leader.roles[user_role])];
    const Vec3& fw = follower_ws[static_cast<std::size_t>(t * follower.clip.joint_count() +
                                                          follower.roles[partner_role])];
    contacts_json.push_back({{"frame", c.frame},
                             {"pair", c.pair},
                             {"user_joint", user_roles.at(user_side + "_wrist")},
                             {"partner_joint", partner_roles.at(partner_side + "_wrist")},
                             {"template_frame", t},
                             {"captured_distance_m", round_um((lw - fw).norm())}});
  }

  const std::vector<int> user_joints = animated_joints(input.clip);
  const std::vector<int> partner_joints = animated_joints(partner.clip);
  json doc;
  doc["fps"] = fps;
  doc["frames"] = frames;
  // Metres per file unit of the two files: the viewers import at this scale.
  doc["metres_per_unit"] = {{"user", user_file.metres_per_unit},
                            {"partner", partner.metres_per_unit}};
  doc["frames_checked"] = checked;
  doc["joints"] = {{"user", names_json(input.clip, user_joints)},
                   {"partner", names_json(partner.clip, partner_joints)}};
  doc["roles"] = {{"user", user_roles}, {"partner", partner_roles}};
  doc["user"] = positions_json(input_ws, input.clip.joint_count(), user_joints, checked);
  doc["partner"] = positions_json(partner_ws, partner.clip.joint_count(), partner_joints, checked);
  doc["contacts"] = contacts_json;
  // The couple's spacing in the capture at the follower's template frame of each checked frame.
  json spacing = json::array();
  for (int f : checked) {
    const int t = trace[static_cast<std::size_t>(f)].template_frame;
    const Vec3 d = leader_ws[static_cast<std::size_t>(t * leader.clip.joint_count() +
                                                      leader.roles[duet::Role::kHips])] -
                   follower_ws[static_cast<std::size_t>(t * follower.clip.joint_count() +
                                                        follower.roles[duet::Role::kHips])];
    spacing.push_back(round_um(std::hypot(d.x(), d.z())));
  }
  doc["captured_hips_distance_m"] = spacing;
  doc["user_file_vs_input_max_m"] = user_vs_input;
  std::ofstream out(out_path);
  out << doc.dump() << "\n";
  if (!out) fail(out_path + ": cannot write");
  std::printf(
      "viewer_reference: %d frames at %g fps, %zu checked (%zu contact frames); user file "
      "vs input %.2g m\n",
      frames, fps, checked.size(), contacts.size(), user_vs_input);
  return 0;
}
