#include "eval_rigs.h"

#include <filesystem>
#include <system_error>

#include "duet/io/motion_argument.h"
#include "duet/io/motion_file.h"
#include "duet/motion/generic_rigs.h"
#include "duet/motion/rig_variants.h"

namespace duet::app {

namespace {

// The data folder's real rigs: where each one's skeleton comes from (the motion is not used).
struct DataRig {
  const char* name;
  const char* word;  // a motion word relative to the data folder
};
constexpr DataRig kDataRigs[] = {
    {"asf", "cmu-salsa/asf-amc/60.asf+cmu-salsa/asf-amc/60_01.amc"},
    {"handshake", "cmu-handshake/18_01.bvh"},
    {"bandai", "bandai/dataset-1_walk_normal_001.bvh"},
};

Result<EvalRig> load_file_rig(const std::string& name, const std::string& word) {
  Result<std::vector<std::string>> paths = split_motion_argument(word);
  if (!paths) return Error{"--rigs " + name + ": " + paths.error().message};
  Result<LoadedMotion> loaded = load_motion(paths.value());
  if (!loaded) return Error{"--rigs " + name + ": " + loaded.error().message};
  return EvalRig{name, loaded.value().clip.skeleton_ptr(), loaded.value().roles};
}

}  // namespace

const std::vector<std::string>& known_eval_rig_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = {"native", "proportioned"};
    for (const DataRig& rig : kDataRigs) all.emplace_back(rig.name);
    for (const GenericRigInfo& rig : generic_rigs()) all.emplace_back(rig.name);
    return all;
  }();
  return names;
}

Result<std::vector<EvalRig>> load_eval_rigs(const std::vector<std::string>& entries,
                                            const std::string& data_dir,
                                            const DuetLibrary& library) {
  std::vector<std::string> expanded;
  for (const std::string& entry : entries) {
    if (entry == "all") {
      for (const std::string& name : known_eval_rig_names()) expanded.push_back(name);
    } else {
      expanded.push_back(entry);
    }
  }
  std::vector<EvalRig> rigs;
  for (const std::string& entry : expanded) {
    if (std::ranges::any_of(rigs, [&](const EvalRig& r) { return r.name == entry; })) continue;
    if (entry == "native") {
      rigs.push_back({"native", nullptr, {}});
      continue;
    }
    const LoadedMotion& tmpl = library.takes()[0].template_motion;
    if (entry == "proportioned") {
      auto rig = std::make_shared<Skeleton>(make_proportioned_rig(
          tmpl.clip.skeleton(), tmpl.roles, RigProportions::evaluation_variant()));
      JointRoles roles = tmpl.roles;
      roles.convention = "proportioned";
      rigs.push_back({"proportioned", std::move(rig), roles});
      continue;
    }
    if (const GenericRigInfo* generic = find_generic_rig(entry); generic != nullptr) {
      Result<GenericRigWithRoles> made = make_generic_rig_with_roles(generic->rig);
      if (!made) return Error{"--rigs " + entry + ": " + made.error().message};
      rigs.push_back({entry, std::make_shared<Skeleton>(std::move(made.value().skeleton)),
                      std::move(made.value().roles)});
      continue;
    }
    const auto data_rig = std::ranges::find_if(
        kDataRigs, [&](const DataRig& r) { return entry == r.name; });
    Result<EvalRig> rig = Error{""};
    if (data_rig != std::end(kDataRigs)) {
      if (data_dir.empty()) {
        return Error{"--rigs " + entry +
                     ": needs the data folder (--data-dir or $DUET_DATA_DIR; "
                     "scripts/get-data.sh prints it)"};
      }
      std::string word = data_rig->word;
      // Each part of the word is relative to the data folder.
      std::string resolved;
      std::size_t begin = 0;
      while (begin <= word.size()) {
        const std::size_t end = std::min(word.find('+', begin), word.size());
        if (!resolved.empty()) resolved += '+';
        resolved += (std::filesystem::path(data_dir) / word.substr(begin, end - begin)).string();
        begin = end + 1;
      }
      rig = load_file_rig(entry, resolved);
    } else {
      std::string known;
      for (const std::string& n : known_eval_rig_names()) known += n + ", ";
      std::error_code ec;  // a name too long for a path is no file either, not an exception
      if (!std::filesystem::exists(entry, ec) && entry.find('+') == std::string::npos) {
        return Error{"--rigs: '" + entry + "' is no rig name (" + known +
                     "all) and no motion file"};
      }
      rig = load_file_rig(std::filesystem::path(entry).stem().string(), entry);
    }
    if (!rig) return rig.error();
    rigs.push_back(std::move(rig).value());
  }
  if (rigs.empty()) return Error{"--rigs: no rig given"};
  return rigs;
}

}  // namespace duet::app
