#include "duet/io/known_datasets.h"

#include <cctype>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

namespace duet {

const std::vector<KnownDataset>& known_datasets() {
  static const std::vector<KnownDataset> datasets = {
      {"cmu-salsa", "the CMU salsa duets (subject 60 leads, subject 61 follows)", "60", "61", 60.0,
       "an AMASS copy of 60_01 fixes 2242 frames at 37.4 s; the 120 in the BVH headers is the "
       "converter's default for all of CMU"},
  };
  return datasets;
}

namespace {

// The CMU subject a file name belongs to: "60" for 60_03_scaled.bvh, 60_01.amc or 60.asf.
std::string cmu_subject(const std::string& path) {
  const std::filesystem::path p(path);
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string stem = p.stem().string();
  std::size_t digits = 0;
  while (digits < stem.size() && std::isdigit(static_cast<unsigned char>(stem[digits]))) ++digits;
  if (digits == 0) return {};
  if (ext == ".asf") return digits == stem.size() ? stem : std::string();
  if (ext != ".bvh" && ext != ".amc") return {};
  // SUBJECT_TRIAL, then anything (cgspeed's "_scaled").
  std::size_t trial = digits + 1;
  if (digits >= stem.size() || stem[digits] != '_') return {};
  while (trial < stem.size() && std::isdigit(static_cast<unsigned char>(stem[trial]))) ++trial;
  if (trial == digits + 1) return {};
  return stem.substr(0, digits);
}

}  // namespace

const KnownDataset* find_known_dataset(const std::string& motion_path) {
  const std::string subject = cmu_subject(motion_path);
  if (subject.empty()) return nullptr;
  for (const KnownDataset& d : known_datasets()) {
    if (subject == d.leader_subject || subject == d.partner_subject) return &d;
  }
  return nullptr;
}

std::string known_dataset_rate_warning(const std::string& motion_path, double file_fps) {
  const KnownDataset* d = find_known_dataset(motion_path);
  if (d == nullptr || !(file_fps > 0.0)) return {};
  if (std::abs(file_fps - d->frame_rate_hz) <= 0.005 * d->frame_rate_hz) return {};
  return fmt::format("{}: read at {:g} fps, but {} are {:g} Hz ({}); pass --fps {:g} or use "
                     "the library file libraries/{}.toml",
                     std::filesystem::path(motion_path).filename().string(), file_fps,
                     d->description, d->frame_rate_hz, d->rate_note, d->frame_rate_hz, d->name);
}

}  // namespace duet
