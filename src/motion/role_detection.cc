#include "duet/motion/role_detection.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "duet/motion/forward_kinematics.h"
#include "duet/motion/up_axis.h"

namespace duet {

namespace {

using Index = std::size_t;
constexpr int kNone = -1;
constexpr int kLeft = 1, kRight = 2;

Index at(int j) { return static_cast<Index>(j); }

// ---- The skeleton as a tree with a rest pose -------------------------------------------------

struct Tree {
  const Skeleton& skeleton;
  std::vector<std::vector<int>> children;
  std::vector<int> depth;   // edges from the root
  std::vector<int> height;  // edges to the deepest leaf below
  std::vector<int> size;    // joints in the subtree, itself included
  std::vector<Vec3> rest;   // rest-pose positions (no rotations), file units
  double tolerance = 0.0;   // offsets shorter than this are "zero length"

  explicit Tree(const Skeleton& s) : skeleton(s) {
    const int n = s.joint_count();
    children.resize(at(n));
    depth.assign(at(n), 0);
    height.assign(at(n), 0);
    size.assign(at(n), 1);
    double longest = 0.0;
    for (int j = 0; j < n; ++j) {
      const int p = s.joints[at(j)].parent;
      if (p >= 0) {
        children[at(p)].push_back(j);
        depth[at(j)] = depth[at(p)] + 1;
      }
      longest = std::max(longest, s.joints[at(j)].offset.norm());
    }
    for (int j = n - 1; j > 0; --j) {  // parents come before children
      const int p = s.joints[at(j)].parent;
      if (p < 0) continue;
      height[at(p)] = std::max(height[at(p)], height[at(j)] + 1);
      size[at(p)] += size[at(j)];
    }
    std::vector<Vec3> translations(at(n));
    for (int j = 0; j < n; ++j) translations[at(j)] = s.joints[at(j)].offset;
    std::vector<Quat> rotations(at(n), Quat::Identity());
    std::vector<Quat> world_rotations(at(n));
    rest.resize(at(n));
    if (n > 0) forward_kinematics(s, translations, rotations, rest, world_rotations);
    tolerance = 1e-3 * longest;
  }

  int parent(int j) const { return skeleton.joints[at(j)].parent; }
  const std::string& name(int j) const { return skeleton.joints[at(j)].name; }
  bool end_site(int j) const { return skeleton.joints[at(j)].end_site; }
  bool same_place(int a, int b) const { return (rest[at(a)] - rest[at(b)]).norm() <= tolerance; }

  bool is_ancestor(int a, int j) const {  // a strictly above j
    for (int p = parent(j); p >= 0; p = parent(p)) {
      if (p == a) return true;
    }
    return false;
  }
  int lowest_common_ancestor(int a, int b) const {
    while (depth[at(a)] > depth[at(b)]) a = parent(a);
    while (depth[at(b)] > depth[at(a)]) b = parent(b);
    while (a != b) {
      a = parent(a);
      b = parent(b);
    }
    return a;
  }
};

// ---- Joint names -----------------------------------------------------------------------------

struct NameInfo {
  int side = 0;          // 0 none, kLeft, kRight
  std::string core;      // the remaining words run together, lower case: "forearm", "upleg"
  bool excluded = false;  // fingers, eyes, twist/roll helpers, End Sites, IK targets
  bool twist = false;     // a twist/roll helper part-way along a bone
};

bool in(std::string_view word, std::initializer_list<std::string_view> words) {
  return std::find(words.begin(), words.end(), word) != words.end();
}

// Words split at separators (_ . : - space ...), at camelCase humps ("lShldr" -> l Shldr,
// "LHipJoint" -> L Hip Joint) and between letters and digits; lower case.
std::vector<std::string> split_words(std::string_view name) {
  std::vector<std::string> words;
  std::string word;
  auto flush = [&] {
    if (!word.empty()) words.push_back(word);
    word.clear();
  };
  for (std::size_t i = 0; i < name.size(); ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (!std::isalnum(c)) {
      flush();
      continue;
    }
    if (!word.empty()) {
      const auto prev = static_cast<unsigned char>(name[i - 1]);
      const bool next_lower =
          i + 1 < name.size() && std::islower(static_cast<unsigned char>(name[i + 1]));
      if ((std::islower(prev) && std::isupper(c)) ||
          (std::isupper(prev) && std::isupper(c) && next_lower) ||
          (std::isdigit(prev) != 0) != (std::isdigit(c) != 0)) {
        flush();
      }
    }
    word += static_cast<char>(std::tolower(c));
  }
  flush();
  return words;
}

NameInfo analyse_name(std::string_view name) {
  // A namespace ("mixamorig:LeftArm", "Armature:Hips") says nothing about the joint.
  if (const auto colon = name.rfind(':'); colon != std::string_view::npos && colon + 1 < name.size()) {
    name.remove_prefix(colon + 1);
  }
  std::vector<std::string> words;
  for (std::string& w : split_words(name)) {
    if (std::isdigit(static_cast<unsigned char>(w[0]))) continue;  // Spine1, Bip01, Toe0
    // Rig prefixes and filler words: mixamorig_, Bip01, Character1_, DEF-, joint_, ...Joint.
    if (in(w, {"mixamorig", "bip", "character", "def", "org", "mch", "jnt", "joint", "bone", "bn",
               "rig", "armature", "skeleton", "skel", "cc", "base", "ctrl", "j", "b"}) &&
        !(w == "base" && !words.empty() && words.back() == "toe")) {
      continue;
    }
    words.push_back(std::move(w));
  }
  NameInfo info;
  for (const std::string& w : words) {
    if (in(w, {"thumb", "index", "middle", "mid", "ring", "pinky", "pinkie", "little", "finger",
               "fingers", "eye", "eyes", "jaw", "tongue", "twist", "roll", "end", "nub", "tip",
               "top", "ik", "fk", "pole", "target", "control", "helper", "share", "nose", "ear",
               "hair", "breast", "carpal", "metacarpal", "prop", "weapon", "heel"})) {
      info.excluded = true;
    }
    if (w == "twist" || w == "roll") info.twist = true;
  }
  // Side: a Left/Right word anywhere, or L/R as the first or last word (lShldr, L_Hand, hand.L).
  auto side_of = [](const std::string& w) {
    if (w == "left" || w == "l" || w == "lf" || w == "lft") return kLeft;
    if (w == "right" || w == "r" || w == "rt" || w == "rgt") return kRight;
    return 0;
  };
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] == "left" || words[i] == "right") {
      info.side = side_of(words[i]);
      words.erase(words.begin() + static_cast<std::ptrdiff_t>(i));
      break;
    }
  }
  if (info.side == 0 && words.size() >= 2) {
    if (const int s = side_of(words.front()); s != 0) {
      info.side = s;
      words.erase(words.begin());
    } else if (const int t = side_of(words.back()); t != 0) {
      info.side = t;
      words.pop_back();
    }
  }
  for (const std::string& w : words) info.core += w;
  return info;
}

// What a name says a joint is, with a priority (higher = more specific).
enum class Part { kElbow, kWrist, kKnee, kAnkle, kToe, kFootAsToe, kHead, kNeck };

int name_priority(const NameInfo& info, Part part) {
  if (info.excluded) return -1;
  const std::string& c = info.core;
  switch (part) {
    case Part::kElbow:
      return in(c, {"forearm", "lowerarm", "lowarm", "elbow", "radius", "ulna", "forarm"}) ? 2 : -1;
    case Part::kWrist:
      return c == "wrist" ? 2 : c == "hand" ? 1 : -1;
    case Part::kKnee:
      if (c == "knee") return 2;
      return in(c, {"shin", "calf", "lowerleg", "lowleg", "leg", "tibia", "shank", "crus"}) ? 1 : -1;
    case Part::kAnkle:
      return c == "ankle" ? 2 : c == "foot" ? 1 : -1;
    case Part::kToe:
      return in(c, {"toe", "toes", "toebase", "ball", "forefoot", "toebone"}) ? 2 : -1;
    case Part::kFootAsToe:  // SMPL: left_foot lies below left_ankle
      return c == "foot" ? 1 : -1;
    case Part::kHead:
      return c == "head" ? 2 : c == "skull" ? 1 : -1;
    case Part::kNeck:
      return c == "neck" ? 2 : -1;
  }
  return -1;
}

const char* side_word(int side) { return side == kLeft ? "left" : "right"; }

std::string quoted_joint(const Tree& tree, int j) { return "'" + tree.name(j) + "'"; }

// ---- Shared structure rules ------------------------------------------------------------------

// The joint that rotates the bone ending at `j`: the nearest ancestor at another place, skipping
// zero-length joints and twist/roll helpers, so an elbow's gives the upper arm and a knee's the
// thigh whatever the rig calls them.
int joint_above(const Tree& tree, int j, const std::vector<NameInfo>& names) {
  int p = tree.parent(j);
  while (p >= 0) {
    if (!tree.same_place(p, j) && !names[at(p)].twist) return p;
    p = tree.parent(p);
  }
  return kNone;
}

struct Detector {
  const Tree& tree;
  const std::vector<NameInfo>& names;
  RoleDetection& out;

  void set(Role role, int joint, std::string note) {
    out.roles.joints[at(static_cast<int>(role))] = joint;
    out.notes[at(static_cast<int>(role))] = std::move(note);
  }
  int get(Role role) const { return out.roles[role]; }

  // Hips, chest, spine, neck and head once both thighs and both upper arms are known.
  void find_trunk(int head_branch) {
    const int lh = get(Role::kLeftHip), rh = get(Role::kRightHip);
    const int ls = get(Role::kLeftShoulder), rs = get(Role::kRightShoulder);
    if (lh >= 0 && rh >= 0 && lh != rh) {
      set(Role::kHips, tree.lowest_common_ancestor(lh, rh), "where the two legs meet");
    }
    if (ls >= 0 && rs >= 0 && ls != rs) {
      set(Role::kChest, tree.lowest_common_ancestor(ls, rs), "where the two arms meet");
    }
    const int hips = get(Role::kHips), chest = get(Role::kChest);
    if (chest < 0) return;
    if (hips >= 0) {  // the spine lies between the two; without legs only the top is found
      if (chest != hips && !tree.is_ancestor(hips, chest)) {
        out.notes[at(static_cast<int>(Role::kChest))] =
            "the arms meet at " + quoted_joint(tree, chest) + ", which is not above the legs' " +
            quoted_joint(tree, hips);
        out.roles.joints[at(static_cast<int>(Role::kChest))] = kNone;
        return;
      }
      const int above = joint_above(tree, chest, names);
      if (chest != hips && above >= 0 && above != hips && tree.is_ancestor(hips, above)) {
        set(Role::kSpine, above, "the spine joint below the chest");
      } else {
        set(Role::kSpine, chest, "no spine joint between hips and chest: the chest's");
      }
    } else {
      out.notes[at(static_cast<int>(Role::kHips))] = "no legs to meet";
      out.notes[at(static_cast<int>(Role::kSpine))] = "no hips to start from";
    }
    // Head: by name below the chest, else the end of the branch that holds neither arm.
    int head = kNone, best = -1;
    for (int j = 0; j < tree.skeleton.joint_count(); ++j) {
      const int priority = name_priority(names[at(j)], Part::kHead);
      if (priority < 0 || !tree.is_ancestor(chest, j)) continue;
      if (tree.is_ancestor(j, ls) || tree.is_ancestor(j, rs) || j == ls || j == rs) continue;
      if (priority > best || (priority == best && tree.depth[at(j)] < tree.depth[at(head)])) {
        head = j;
        best = priority;
      }
    }
    std::string head_note = "named " + (head >= 0 ? quoted_joint(tree, head) : std::string());
    if (head < 0) {
      if (head_branch < 0) {
        for (int c : tree.children[at(chest)]) {
          if (tree.end_site(c) || c == ls || c == rs || tree.is_ancestor(c, ls) ||
              tree.is_ancestor(c, rs)) {
            continue;
          }
          if (head_branch < 0 || tree.size[at(c)] > tree.size[at(head_branch)]) head_branch = c;
        }
      }
      if (head_branch < 0) {
        out.notes[at(static_cast<int>(Role::kHead))] =
            "no joint named head and no branch above the chest " + quoted_joint(tree, chest) +
            " besides the arms";
        return;
      }
      head = head_branch;  // down the branch while it does not fork or end
      while (tree.children[at(head)].size() == 1 && !tree.end_site(tree.children[at(head)][0])) {
        head = tree.children[at(head)][0];
      }
      head_note = "the end of the neck branch above the chest";
    }
    set(Role::kHead, head, head_note);
    // Neck: the highest neck-named joint between chest and head, else the joint below the chest
    // on the way to the head.
    int neck = kNone, first_below_chest = kNone;
    for (int j = tree.parent(head); j >= 0 && j != chest; j = tree.parent(j)) {
      first_below_chest = j;
      if (name_priority(names[at(j)], Part::kNeck) >= 0) neck = j;
    }
    if (neck >= 0) {
      set(Role::kNeck, neck, "named " + quoted_joint(tree, neck));
    } else if (first_below_chest >= 0) {
      set(Role::kNeck, first_below_chest, "the joint above the chest on the way to the head");
    } else {
      set(Role::kNeck, head, "no joint between chest and head: the head's");
    }
  }

  void finish(const std::string& method) {
    out.roles.convention = method;
    std::ostringstream problem;
    for (int r = 0; r < kRoleCount; ++r) {
      if (out.roles.joints[at(r)] >= 0) continue;
      if (problem.tellp() > 0) problem << "; ";
      problem << role_name(static_cast<Role>(r));
      if (!out.notes[at(r)].empty()) problem << " (" << out.notes[at(r)] << ")";
    }
    if (problem.tellp() > 0) out.problem = "missing roles " + problem.str();
  }
};

RoleDetection empty_detection() {
  RoleDetection d;
  d.roles.joints.fill(kNone);
  return d;
}

// The joint with the best name for `part` on `side` (0: any side) among `allowed`, shallowest
// on ties.
template <typename Allowed>
int best_named(const Tree& tree, const std::vector<NameInfo>& names, Part part, int side,
               Allowed allowed) {
  int best = kNone, best_priority = -1;
  for (int j = 0; j < tree.skeleton.joint_count(); ++j) {
    const int priority = name_priority(names[at(j)], part);
    if (priority < 0 || names[at(j)].side != side || !allowed(j)) continue;
    if (priority > best_priority ||
        (priority == best_priority && tree.depth[at(j)] < tree.depth[at(best)])) {
      best = j;
      best_priority = priority;
    }
  }
  return best;
}

}  // namespace

std::vector<Role> RoleDetection::missing_roles() const {
  std::vector<Role> missing;
  for (int r = 0; r < kRoleCount; ++r) {
    if (roles.joints[at(r)] < 0) missing.push_back(static_cast<Role>(r));
  }
  return missing;
}

RoleDetection detect_roles_by_name(const Skeleton& skeleton) {
  RoleDetection out = empty_detection();
  const Tree tree(skeleton);
  std::vector<NameInfo> names;
  for (const Joint& j : skeleton.joints) names.push_back(analyse_name(j.name));
  Detector d{tree, names, out};
  auto any = [](int) { return true; };

  for (int side : {kLeft, kRight}) {
    const bool left = side == kLeft;
    const std::string where = std::string(" on the ") + side_word(side) + " side";
    // Arm: the hand/wrist by name, the forearm/elbow above it, the upper arm above that.
    const Role wrist_role = left ? Role::kLeftWrist : Role::kRightWrist;
    const Role elbow_role = left ? Role::kLeftElbow : Role::kRightElbow;
    const Role shoulder_role = left ? Role::kLeftShoulder : Role::kRightShoulder;
    const int wrist = best_named(tree, names, Part::kWrist, side, any);
    if (wrist < 0) {
      d.set(wrist_role, kNone, "no joint named like a hand or wrist" + where);
    } else {
      d.set(wrist_role, wrist, "named " + quoted_joint(tree, wrist));
      int elbow = best_named(tree, names, Part::kElbow, side,
                             [&](int j) { return tree.is_ancestor(j, wrist); });
      if (elbow >= 0) {
        d.set(elbow_role, elbow, "named " + quoted_joint(tree, elbow));
      } else {
        elbow = joint_above(tree, wrist, names);
        d.set(elbow_role, elbow, "the joint above the wrist");
      }
      if (elbow >= 0) {
        const int shoulder = joint_above(tree, elbow, names);
        d.set(shoulder_role, shoulder,
              shoulder >= 0 ? "the joint above the elbow (the upper arm), named " +
                                  quoted_joint(tree, shoulder)
                            : "nothing above the elbow");
      }
    }
    // Leg: the foot/ankle by name, the shin/knee above it, the thigh above that, the toe below.
    const Role ankle_role = left ? Role::kLeftAnkle : Role::kRightAnkle;
    const Role knee_role = left ? Role::kLeftKnee : Role::kRightKnee;
    const Role hip_role = left ? Role::kLeftHip : Role::kRightHip;
    const Role toe_role = left ? Role::kLeftToe : Role::kRightToe;
    const int ankle = best_named(tree, names, Part::kAnkle, side, any);
    if (ankle < 0) {
      d.set(ankle_role, kNone, "no joint named like a foot or ankle" + where);
      continue;
    }
    d.set(ankle_role, ankle, "named " + quoted_joint(tree, ankle));
    int knee = best_named(tree, names, Part::kKnee, side,
                          [&](int j) { return tree.is_ancestor(j, ankle); });
    if (knee >= 0) {
      d.set(knee_role, knee, "named " + quoted_joint(tree, knee));
    } else {
      knee = joint_above(tree, ankle, names);
      d.set(knee_role, knee, "the joint above the ankle");
    }
    if (knee >= 0) {
      const int hip = joint_above(tree, knee, names);
      d.set(hip_role, hip,
            hip >= 0 ? "the joint above the knee (the thigh), named " + quoted_joint(tree, hip)
                     : "nothing above the knee");
    }
    auto below_ankle = [&](int j) { return tree.is_ancestor(ankle, j); };
    int toe = best_named(tree, names, Part::kToe, side, below_ankle);
    std::string toe_note = "named ";
    if (toe < 0) toe = best_named(tree, names, Part::kFootAsToe, side, below_ankle);
    if (toe < 0) {
      // The first joint past the ankle on its longest branch (often the End Site).
      for (int j = ankle; toe < 0 && !tree.children[at(j)].empty();) {
        int next = tree.children[at(j)][0];
        for (int c : tree.children[at(j)]) {
          if (tree.height[at(c)] > tree.height[at(next)]) next = c;
        }
        if (!tree.same_place(next, ankle)) toe = next;
        j = next;
      }
      toe_note = "the joint past the ankle, ";
    }
    d.set(toe_role, toe, toe >= 0 ? toe_note + quoted_joint(tree, toe) : "nothing below the ankle");
  }
  d.find_trunk(kNone);
  d.finish("names");
  // Two sides that are one joint mean the names' sides were wrong.
  for (auto [l, r] : {std::pair{Role::kLeftWrist, Role::kRightWrist},
                      std::pair{Role::kLeftHip, Role::kRightHip}}) {
    if (out.roles[l] >= 0 && out.roles[l] == out.roles[r]) {
      out.problem = "left and right " + std::string(role_name(l)).substr(5) + " are one joint";
    }
  }
  return out;
}

RoleDetection detect_roles_by_hierarchy(const Skeleton& skeleton) {
  RoleDetection out = empty_detection();
  out.roles.convention = "hierarchy";
  const Tree tree(skeleton);
  const int n = skeleton.joint_count();
  std::vector<NameInfo> names(at(n));  // names are not used: nothing excluded
  Detector d{tree, names, out};
  auto fail = [&](std::string why) {
    out = empty_detection();
    out.roles.convention = "hierarchy";
    out.problem = std::move(why);
    return out;
  };

  // Chest: down a spine branch to the first joint where three branches fork (arms, neck).
  std::vector<int> forks;
  auto find_chest = [&](int spine_first) {
    for (int j = spine_first;;) {
      forks.clear();
      for (int c : tree.children[at(j)]) {
        if (tree.height[at(c)] >= 1) forks.push_back(c);
      }
      if (forks.size() >= 3) return j;
      if (tree.children[at(j)].empty()) return kNone;
      int next = tree.children[at(j)][0];
      for (int c : tree.children[at(j)]) {
        if (tree.size[at(c)] > tree.size[at(next)]) next = c;
      }
      j = next;
    }
  };
  // Hips: the first joint where three chains of three or more joints branch (two legs, spine)
  // and whose biggest branch holds the chest (a hand whose fingers fork is not the hips).
  int hips = kNone, chest = kNone;
  bool any_fork = false;
  std::vector<int> branches;
  for (int j = 0; j < n && hips < 0; ++j) {
    branches.clear();
    for (int c : tree.children[at(j)]) {
      if (tree.height[at(c)] >= 2) branches.push_back(c);
    }
    if (branches.size() < 3) continue;
    any_fork = true;
    std::sort(branches.begin(), branches.end(),
              [&](int a, int b) { return tree.size[at(a)] > tree.size[at(b)]; });
    chest = find_chest(branches[0]);
    if (chest >= 0) hips = j;
  }
  if (hips < 0) {
    return fail(any_fork ? "no legs: no joint where two legs and a spine with two arms and a "
                           "neck branch"
                         : "no legs: no joint where two legs and a spine branch (each a chain "
                           "of three or more joints)");
  }
  // The rest pose's up: the spine's direction from the hips to the chest, to the nearest axis. A
  // Y-up rig stands along +Y; a Z-up one (3ds Max, Motive) along +Z.
  const Vec3 up = up_axis_vector(nearest_axis(tree.rest[at(chest)] - tree.rest[at(hips)]));
  // The legs: besides the spine (the biggest branch), the two that reach lowest in the rest pose.
  auto lowest = [&](int root) {
    double height = tree.rest[at(root)].dot(up);
    for (int j = root; j < n; ++j) {
      if (j == root || tree.is_ancestor(root, j)) {
        height = std::min(height, tree.rest[at(j)].dot(up));
      }
    }
    return height;
  };
  std::vector<int> legs(branches.begin() + 1, branches.end());
  std::sort(legs.begin(), legs.end(), [&](int a, int b) { return lowest(a) < lowest(b); });
  legs.resize(2);

  // A leg: thigh and shin are its two longest consecutive bones along its longest chain.
  struct Leg {
    int thigh = kNone, knee = kNone, ankle = kNone, toe = kNone;
  };
  auto find_leg = [&](int first) {
    std::vector<std::vector<int>> groups{{hips}};  // joints at one place
    for (int j = first;;) {
      if (tree.same_place(j, groups.back().back())) {
        groups.back().push_back(j);
      } else {
        groups.push_back({j});
      }
      if (tree.children[at(j)].empty()) break;
      int next = tree.children[at(j)][0];
      for (int c : tree.children[at(j)]) {
        if (tree.height[at(c)] > tree.height[at(next)]) next = c;
      }
      j = next;
    }
    // The joint of a group that rotates the next bone: its deepest joint that is not an End Site.
    auto rep = [&](const std::vector<int>& g) {
      for (auto it = g.rbegin(); it != g.rend(); ++it) {
        if (!tree.end_site(*it)) return *it;
      }
      return g.back();
    };
    Leg leg;
    double best = 0.0;
    for (std::size_t i = 0; i + 2 < groups.size(); ++i) {
      const double a = (tree.rest[at(groups[i + 1][0])] - tree.rest[at(groups[i][0])]).norm();
      const double b = (tree.rest[at(groups[i + 2][0])] - tree.rest[at(groups[i + 1][0])]).norm();
      if (a + b > best) {
        best = a + b;
        leg.thigh = rep(groups[i]);
        leg.knee = rep(groups[i + 1]);
        leg.ankle = rep(groups[i + 2]);
        leg.toe = i + 3 < groups.size() ? rep(groups[i + 3]) : kNone;
      }
    }
    return leg;
  };
  Leg leg_a = find_leg(legs[0]), leg_b = find_leg(legs[1]);
  if (leg_a.ankle < 0 || leg_b.ankle < 0 || leg_a.thigh == hips || leg_b.thigh == hips) {
    return fail("no legs: the branches below the hips have no thigh and shin bones");
  }
  if (leg_a.toe < 0 || leg_b.toe < 0) {
    return fail("a leg ends at the ankle: no toe joint or End Site to tell forward from");
  }

  // The neck rises from the chest; the arms go out sideways or down (T or A pose).
  auto rise = [&](int c) {
    int j = c;
    while (!tree.children[at(j)].empty()) {
      int next = tree.children[at(j)][0];
      for (int k : tree.children[at(j)]) {
        if (tree.height[at(k)] > tree.height[at(next)]) next = k;
      }
      j = next;
    }
    const Vec3 v = tree.rest[at(j)] - tree.rest[at(chest)];
    return v.dot(up) - (v - v.dot(up) * up).norm();
  };
  std::sort(forks.begin(), forks.end(), [&](int a, int b) { return rise(a) > rise(b); });
  const int neck_branch = forks[0];
  std::vector<int> arms(forks.begin() + 1, forks.end());
  std::sort(arms.begin(), arms.end(),
            [&](int a, int b) { return tree.size[at(a)] > tree.size[at(b)]; });
  arms.resize(2);

  // An arm: the hand is where the fingers fork, or the last joint; the forearm and the upper arm
  // are the joints above it.
  struct Arm {
    int shoulder = kNone, elbow = kNone, wrist = kNone;
  };
  auto find_arm = [&](int first) {
    Arm arm;
    int j = first;
    while (tree.children[at(j)].size() == 1 && !tree.end_site(tree.children[at(j)][0])) {
      j = tree.children[at(j)][0];
    }
    arm.wrist = j;
    arm.elbow = joint_above(tree, arm.wrist, names);
    if (arm.elbow >= 0) arm.shoulder = joint_above(tree, arm.elbow, names);
    return arm;
  };
  Arm arm_a = find_arm(arms[0]), arm_b = find_arm(arms[1]);
  for (const Arm* arm : {&arm_a, &arm_b}) {
    if (arm->shoulder < 0 || !tree.is_ancestor(chest, arm->shoulder)) {
      return fail("an arm below the chest '" + tree.name(chest) +
                  "' has fewer than three joints (upper arm, forearm, hand)");
    }
  }

  // Left = up x forward, forward = where the toes point, on the floor: a Y-up body facing +Z has
  // its left at +X.
  Vec3 forward = (tree.rest[at(leg_a.toe)] - tree.rest[at(leg_a.ankle)]) +
                 (tree.rest[at(leg_b.toe)] - tree.rest[at(leg_b.ankle)]);
  forward -= forward.dot(up) * up;
  const double leg_scale = (tree.rest[at(leg_a.ankle)] - tree.rest[at(leg_a.knee)]).norm();
  if (!(forward.norm() > 0.1 * leg_scale)) {
    return fail("cannot tell left from right: the toes point nowhere in the rest pose");
  }
  const Vec3 leftward = up.cross(forward.normalized());
  const double leg_side = (tree.rest[at(leg_a.thigh)] - tree.rest[at(leg_b.thigh)]).dot(leftward);
  const double arm_side =
      (tree.rest[at(arm_a.elbow)] - tree.rest[at(arm_b.elbow)]).dot(leftward);
  if (std::abs(leg_side) <= tree.tolerance || std::abs(arm_side) <= tree.tolerance) {
    return fail("cannot tell left from right: the legs or the arms do not lie side by side in "
                "the rest pose");
  }
  const Leg& left_leg = leg_side > 0 ? leg_a : leg_b;
  const Leg& right_leg = leg_side > 0 ? leg_b : leg_a;
  const Arm& left_arm = arm_side > 0 ? arm_a : arm_b;
  const Arm& right_arm = arm_side > 0 ? arm_b : arm_a;
  const std::string leg_why = " (two longest bones of the leg; left = up x toes' forward)";
  d.set(Role::kLeftHip, left_leg.thigh, "thigh" + leg_why);
  d.set(Role::kLeftKnee, left_leg.knee, "knee" + leg_why);
  d.set(Role::kLeftAnkle, left_leg.ankle, "ankle" + leg_why);
  d.set(Role::kLeftToe, left_leg.toe, "the joint past the ankle");
  d.set(Role::kRightHip, right_leg.thigh, "thigh" + leg_why);
  d.set(Role::kRightKnee, right_leg.knee, "knee" + leg_why);
  d.set(Role::kRightAnkle, right_leg.ankle, "ankle" + leg_why);
  d.set(Role::kRightToe, right_leg.toe, "the joint past the ankle");
  const std::string arm_why = " (hand = where the fingers fork or the arm ends)";
  d.set(Role::kLeftWrist, left_arm.wrist, "hand" + arm_why);
  d.set(Role::kLeftElbow, left_arm.elbow, "the joint above the hand");
  d.set(Role::kLeftShoulder, left_arm.shoulder, "the joint above the elbow");
  d.set(Role::kRightWrist, right_arm.wrist, "hand" + arm_why);
  d.set(Role::kRightElbow, right_arm.elbow, "the joint above the hand");
  d.set(Role::kRightShoulder, right_arm.shoulder, "the joint above the elbow");
  d.find_trunk(neck_branch);
  d.finish("hierarchy");
  return out;
}

RoleDetection detect_roles_report(const Skeleton& skeleton) {
  std::ostringstream why;
  for (const SkeletonMap& map : builtin_skeleton_maps()) {
    RoleDetection exact = empty_detection();
    std::string missing;
    if (resolve_roles(skeleton, map, exact.roles, missing)) {
      for (int r = 0; r < kRoleCount; ++r) {
        exact.notes[at(r)] = "built-in map " + map.name + ": '" + map.joint_names[at(r)] + "'";
      }
      return exact;
    }
    why << "\n  " << map.name << ": missing roles " << missing;
  }
  RoleDetection by_name = detect_roles_by_name(skeleton);
  if (by_name.complete()) return by_name;
  RoleDetection by_hierarchy = detect_roles_by_hierarchy(skeleton);
  if (by_hierarchy.complete()) return by_hierarchy;
  // Neither worked: keep what the names found (it says role by role what is missing).
  by_name.problem =
      "the skeleton matches no known convention, and its roles cannot be found from the joint "
      "names or the hierarchy (give a skeleton map file with --map):" +
      why.str() + "\n  by joint names: " + by_name.problem +
      "\n  by hierarchy: " + by_hierarchy.problem;
  by_name.roles.convention = "none";
  return by_name;
}

}  // namespace duet
