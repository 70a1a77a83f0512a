#include "duet/live/library_file.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include "duet/io/known_datasets.h"
#include "duet/io/motion_argument.h"
#include "duet/motion/limits.h"

namespace duet {

namespace fs = std::filesystem;

std::string library_data_dir(const std::string& data_dir) {
  std::string dir = data_dir;
  if (dir.empty()) {
    const char* env = std::getenv("DUET_DATA_DIR");
    if (env != nullptr) dir = env;
  }
  // Relative to where the user is, not to the library file that says ${data}.
  if (dir.empty()) return dir;
  std::error_code ec;
  const fs::path absolute = fs::absolute(dir, ec);
  return ec ? dir : absolute.lexically_normal().string();
}

namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    default:
      return "a date or time";
  }
}

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

// Reads one library file; every error goes through fail() so it names the file and line.
class FileReader {
 public:
  FileReader(std::string path, std::string data_dir)
      : path_(std::move(path)), data_dir_(library_data_dir(data_dir)) {}

  Result<LibrarySpec> read() {
    std::ifstream in(path_, std::ios::binary);
    if (!in || fs::is_directory(path_)) return make_error(path_, 0, "cannot open the library file");
    std::stringstream text;
    text << in.rdbuf();
    toml::table root;
    try {
      root = toml::parse(text.str(), path_);
    } catch (const toml::parse_error& e) {
      return make_error(
          path_, static_cast<int>(e.source().begin.line),
          std::string("not a valid TOML library file: ") + std::string(e.description()));
    }
    spec_.source = path_;
    if (!read_top(root)) return error_;
    return std::move(spec_);
  }

 private:
  bool fail(int line, const std::string& reason) {
    error_ = make_error(path_, line, reason);
    return false;
  }
  bool fail_type(const std::string& key, const toml::node& node, const char* expected) {
    return fail(line_of(node),
                "key '" + key + "' must be " + expected + ", not " + type_name(node));
  }

  bool get_string(const std::string& key, const toml::node& node, std::string& out) {
    if (!node.is_string()) return fail_type(key, node, "a string");
    out = *node.value<std::string>();
    return true;
  }
  // A number within [low, high] (nan and inf are not).
  bool get_between(const std::string& key, const toml::node& node, double low, double high,
                   const std::string& unit, std::optional<double>& out) {
    if (!node.is_number()) return fail_type(key, node, "a number");
    const double v = *node.value<double>();
    if (!(v >= low && v <= high)) {
      return fail(line_of(node), fmt::format("key '{}' must be between {:g} and {:g} {}, got {:g}",
                                             key, low, high, unit, v));
    }
    out = v;
    return true;
  }

  // "${data}/x" -> "<data dir>/x"; no other variables exist.
  bool expand(const std::string& key, const toml::node& node, std::string& path) {
    const std::size_t at = path.find("${");
    if (at == std::string::npos) return true;
    const std::size_t end = path.find('}', at);
    const std::string var = path.substr(at, end == std::string::npos ? end : end - at + 1);
    if (var != "${data}") {
      return fail(line_of(node), "key '" + key + "': unknown variable " + var +
                                     " (the only one is ${data}, the data directory)");
    }
    if (data_dir_.empty()) {
      return fail(line_of(node), "key '" + key +
                                     "' uses ${data}, the data directory: give --data-dir DIR or "
                                     "set DUET_DATA_DIR (scripts/get-data.sh prints it)");
    }
    path.replace(at, var.size(), data_dir_);
    return expand(key, node, path);
  }

  bool read_top(const toml::table& root) {
    static const std::set<std::string> known = {"name", "description", "fps",     "scale",
                                                "trim", "root",        "dancers", "pair"};
    for (auto&& [k, node] : root) {
      const std::string key(k.str());
      if (!known.contains(key)) {
        return fail(static_cast<int>(k.source().begin.line),
                    "unknown key '" + key +
                        "' (known: name, description, fps, scale, trim, root, dancers, pair)");
      }
      if (key == "name" && !get_string(key, node, spec_.name)) return false;
      if (key == "description" && !get_string(key, node, spec_.description)) return false;
      if (key == "fps" && !get_between(key, node, kMinFrameRate, kMaxFrameRate, "fps",
                                       spec_.frame_rate)) {
        return false;
      }
      if (key == "scale" && !get_between(key, node, kMinMetresPerUnit, kMaxMetresPerUnit,
                                         "metres per file unit", spec_.metres_per_unit)) {
        return false;
      }
      if (key == "trim") {
        if (!node.is_boolean()) return fail_type(key, node, "true or false");
        spec_.trim_to_shorter = *node.value<bool>();
      }
      if (key == "dancers" && !read_dancers(node)) return false;
    }
    // Where relative paths start: the file's directory, or `root` (itself relative to it).
    root_ = fs::absolute(path_).parent_path();
    if (const toml::node* node = root.get("root")) {
      std::string text;
      if (!get_string("root", *node, text) || !expand("root", *node, text)) return false;
      root_ = (root_ / text).lexically_normal();
      std::error_code ec;
      if (!fs::is_directory(root_, ec)) {
        return fail(line_of(*node), "key 'root': no such directory: " + root_.string());
      }
    }
    const toml::node* pairs = root.get("pair");
    if (pairs == nullptr) {
      return fail(0, "no pairs: add [[pair]] tables with leader = \"...\" and partner = \"...\"");
    }
    const toml::array* array = pairs->as_array();
    if (array == nullptr) return fail_type("pair", *pairs, "an array of [[pair]] tables");
    if (array->empty()) return fail(line_of(*pairs), "key 'pair' has no pairs");
    for (std::size_t i = 0; i < array->size(); ++i) {
      if (!read_pair(static_cast<int>(i) + 1, (*array)[i])) return false;
    }
    return true;
  }

  bool read_dancers(const toml::node& node) {
    const toml::table* table = node.as_table();
    if (table == nullptr) return fail_type("dancers", node, "a table");
    for (auto&& [k, value] : *table) {
      const std::string key(k.str());
      if (key == "leader") {
        if (!get_string("dancers.leader", value, spec_.leader_name)) return false;
      } else if (key == "partner") {
        if (!get_string("dancers.partner", value, spec_.partner_name)) return false;
      } else {
        return fail(static_cast<int>(k.source().begin.line),
                    "unknown key 'dancers." + key + "' (known: leader, partner)");
      }
    }
    return true;
  }

  bool read_pair(int index, const toml::node& node) {
    const std::string where = fmt::format("pair {}", index);
    const toml::table* table = node.as_table();
    if (table == nullptr) return fail_type(where, node, "a table");
    PairFiles pair;
    for (auto&& [k, value] : *table) {
      const std::string key(k.str());
      const std::string full = where + "." + key;
      if (key == "name") {
        if (!get_string(full, value, pair.name)) return false;
      } else if (key == "leader" || key == "partner") {
        if (!read_member(full, value, key == "leader" ? pair.leader : pair.partner)) return false;
      } else {
        return fail(static_cast<int>(k.source().begin.line),
                    "unknown key '" + full + "' (known: name, leader, partner)");
      }
    }
    for (const char* member : {"leader", "partner"}) {
      if (!table->contains(member)) {
        return fail(line_of(node),
                    where + " has no '" + member + "' (a .bvh path, or [\"x.asf\", \"y.amc\"])");
      }
    }
    spec_.pairs.push_back(std::move(pair));
    return true;
  }

  // "take.bvh" or ["skeleton.asf", "motion.amc"]; every file must exist.
  bool read_member(const std::string& key, const toml::node& node, MotionFiles& files) {
    std::vector<const toml::node*> items;
    if (const toml::array* array = node.as_array()) {
      for (const toml::node& item : *array) items.push_back(&item);
    } else {
      items.push_back(&node);
    }
    if (items.empty() || items.size() > 2 ||
        !std::ranges::all_of(items, [](const toml::node* n) { return n->is_string(); })) {
      return fail_type(key, node, "a .bvh path or an array [\"skeleton.asf\", \"motion.amc\"]");
    }
    for (const toml::node* item : items) {
      std::string text = *item->value<std::string>();
      if (!expand(key, *item, text)) return false;
      const fs::path p = (root_ / text).lexically_normal();  // an absolute `text` stays as is
      if (!is_file(p))
        return fail(line_of(*item), "key '" + key + "': no such file: " + p.string());
      files.push_back(p.string());
    }
    std::vector<std::string> ext;
    for (const std::string& f : files) ext.push_back(lower_extension(f));
    const bool bvh = files.size() == 1 && ext[0] == ".bvh";
    const bool asf_amc = files.size() == 2 && ((ext[0] == ".asf" && ext[1] == ".amc") ||
                                               (ext[0] == ".amc" && ext[1] == ".asf"));
    if (!bvh && !asf_amc) {
      return fail(line_of(node), "key '" + key +
                                     "': a dancer is one .bvh file or [\"skeleton.asf\", "
                                     "\"motion.amc\"], not " +
                                     join_motion_argument(files));
    }
    if (asf_amc && ext[0] == ".amc") std::swap(files[0], files[1]);
    return true;
  }

  std::string path_;
  std::string data_dir_;
  fs::path root_;
  LibrarySpec spec_;
  Error error_;
};

// SUBJECT_TRIAL*.bvh / .amc -> (subject, trial); SUBJECT.asf -> (subject, "").
bool parse_cmu_name(const fs::path& p, std::string& subject, std::string& trial) {
  const std::string stem = p.stem().string();
  std::size_t i = 0;
  while (i < stem.size() && std::isdigit(static_cast<unsigned char>(stem[i]))) ++i;
  if (i == 0) return false;
  subject = stem.substr(0, i);
  const std::string ext = lower_extension(p);
  if (ext == ".asf") {
    trial.clear();
    return i == stem.size();
  }
  if ((ext != ".bvh" && ext != ".amc") || i >= stem.size() || stem[i] != '_') return false;
  std::size_t j = i + 1;
  while (j < stem.size() && std::isdigit(static_cast<unsigned char>(stem[j]))) ++j;
  if (j == i + 1) return false;
  trial = stem.substr(i + 1, j - i - 1);
  return true;
}

// Whether the digit string `a` is a smaller number than `b`, at any length (std::stoll throws
// past 19 digits).
bool smaller_number(const std::string& a, const std::string& b) {
  const auto digits = [](const std::string& s) {
    const std::size_t first = s.find_first_not_of('0');
    return first == std::string::npos ? std::string() : s.substr(first);
  };
  const std::string x = digits(a), y = digits(b);
  return x.size() != y.size() ? x.size() < y.size() : x < y;
}

Result<LibrarySpec> recognise_pairs(const fs::path& dir) {
  // subject -> trial -> files by extension; subject -> .asf
  std::map<std::string, std::map<std::string, std::map<std::string, std::vector<fs::path>>>> takes;
  std::map<std::string, std::vector<fs::path>> skeletons;
  std::error_code ec;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec);
  if (ec) return make_error(dir.string(), 0, "cannot read the directory: " + ec.message());
  for (; it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) return make_error(dir.string(), 0, "cannot read the directory: " + ec.message());
    const fs::path& p = it->path();
    if (p.filename().string().starts_with(".")) {
      if (it->is_directory(ec)) it.disable_recursion_pending();
      continue;
    }
    if (it->is_directory(ec)) {
      if (it.depth() >= 2) it.disable_recursion_pending();  // three levels: data/60/x.bvh
      continue;
    }
    std::string subject, trial;
    if (!it->is_regular_file(ec) || !parse_cmu_name(p, subject, trial)) continue;
    if (trial.empty()) {
      skeletons[subject].push_back(p);
    } else {
      takes[subject][trial][lower_extension(p)].push_back(p);
    }
  }
  const std::string what =
      "no library file (library.toml) and no duets recognised: expected the files of two "
      "subjects named SUBJECT_TRIAL*.bvh, or SUBJECT.asf with SUBJECT_TRIAL.amc";
  if (takes.size() != 2) {
    if (takes.empty()) return make_error(dir.string(), 0, what);
    std::string subjects;
    for (const auto& [s, unused] : takes) subjects += (subjects.empty() ? "" : ", ") + s;
    return make_error(dir.string(), 0,
                      fmt::format("{}; found {} subject(s) ({}): point --library at a folder "
                                  "with one duet's two dancers, or write a library file",
                                  what, takes.size(), subjects));
  }
  LibrarySpec spec;
  spec.source = dir.string();
  spec.name = dir.filename().string();
  std::string first = takes.begin()->first, second = std::next(takes.begin())->first;
  if (smaller_number(second, first)) std::swap(first, second);
  std::string leader = first, partner = second;
  const KnownDataset* known = nullptr;
  for (const KnownDataset& d : known_datasets()) {
    if ((d.leader_subject == first && d.partner_subject == second) ||
        (d.leader_subject == second && d.partner_subject == first)) {
      known = &d;
    }
  }
  if (known != nullptr) {
    leader = known->leader_subject;
    partner = known->partner_subject;
    spec.frame_rate = known->frame_rate_hz;
    spec.notes.push_back(fmt::format("recognised {}: subject {} leads, {:g} fps", known->name,
                                     leader, known->frame_rate_hz));
  } else {
    spec.notes.push_back("subject " + leader +
                         " taken as the leader (the lower number): write a library file to say "
                         "otherwise");
  }
  spec.leader_name = "subject " + leader;
  spec.partner_name = "subject " + partner;

  // One dancer's take: its BVH, else its skeleton + AMC.
  auto member = [&](const std::string& subject, const std::string& trial,
                    MotionFiles& files) -> Status {
    auto& by_ext = takes[subject][trial];
    for (const char* ext : {".bvh", ".amc"}) {
      const std::vector<fs::path>& found = by_ext[ext];
      if (found.size() > 1) {
        return make_error(
            dir.string(), 0,
            fmt::format("subject {} trial {} has {} {} files ({}, {}, ...): keep one "
                        "or write a library file",
                        subject, trial, found.size(), ext, found[0].string(), found[1].string()));
      }
    }
    if (by_ext[".bvh"].size() == 1) {
      files = {by_ext[".bvh"][0].string()};
    } else if (by_ext[".amc"].size() == 1 && skeletons[subject].size() == 1) {
      files = {skeletons[subject][0].string(), by_ext[".amc"][0].string()};
    }
    return Ok{};
  };
  std::vector<std::string> skipped;
  for (const auto& [trial, unused] : takes[leader]) {
    PairFiles pair;
    pair.name = leader + "_" + trial;
    if (Status s = member(leader, trial, pair.leader); !s) return s.error();
    if (Status s = member(partner, trial, pair.partner); !s) return s.error();
    if (pair.leader.empty() || pair.partner.empty()) {
      skipped.push_back(trial);
      continue;
    }
    spec.pairs.push_back(std::move(pair));
  }
  if (spec.pairs.empty()) {
    return make_error(dir.string(), 0,
                      "subjects " + leader + " and " + partner +
                          " have no trial in common with a motion for both (an .amc needs its "
                          "SUBJECT.asf)");
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& t : skipped) list += (list.empty() ? "" : ", ") + t;
    spec.notes.push_back("trials without both dancers skipped: " + list);
  }
  return spec;
}

}  // namespace

Result<LibrarySpec> read_library_file(const std::string& path, const std::string& data_dir) {
  return FileReader(path, data_dir).read();
}

Result<LibrarySpec> read_library_dir(const std::string& dir, const std::string& data_dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return make_error(dir, 0, "not a directory");
  const fs::path named = fs::path(dir) / "library.toml";
  if (is_file(named)) return read_library_file(named.string(), data_dir);
  std::vector<fs::path> tomls;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (e.is_regular_file(ec) && lower_extension(e.path()) == ".toml") tomls.push_back(e.path());
  }
  if (tomls.size() == 1) return read_library_file(tomls[0].string(), data_dir);
  if (tomls.size() > 1) {
    std::ranges::sort(tomls);
    std::string list;
    for (const fs::path& p : tomls) list += (list.empty() ? "" : ", ") + p.filename().string();
    return make_error(dir, 0,
                      "has " + std::to_string(tomls.size()) + " library files (" + list +
                          "): name one with --library FILE");
  }
  return recognise_pairs(fs::path(dir));
}

Result<LibrarySpec> read_library(const std::string& file_or_dir, const std::string& data_dir) {
  std::error_code ec;
  if (fs::is_directory(file_or_dir, ec)) return read_library_dir(file_or_dir, data_dir);
  if (!fs::exists(file_or_dir, ec))
    return make_error(file_or_dir, 0, "no such library file or directory");
  return read_library_file(file_or_dir, data_dir);
}

}  // namespace duet
