#include "eval_non_dance.h"

#include <filesystem>
#include <system_error>

#include "duet/io/motion_argument.h"

namespace duet::app {

namespace {

constexpr const char* kBandaiClips[] = {"walk", "dance-short", "byebye"};

std::string bandai_path(const std::string& data_dir, const char* clip) {
  return (std::filesystem::path(data_dir) / "bandai" /
          ("dataset-1_" + std::string(clip) + "_normal_001.bvh"))
      .string();
}

Result<NonDanceClip> load_clip(const std::string& name, const std::string& word) {
  Result<std::vector<std::string>> paths = split_motion_argument(word);
  if (!paths) return Error{"--non-dance " + word + ": " + paths.error().message};
  Result<LoadedMotion> loaded = load_motion(paths.value());
  if (!loaded) return Error{"--non-dance " + word + ": " + loaded.error().message};
  if (loaded.value().clip.frame_count() == 0) return Error{"--non-dance " + word + ": no frames"};
  return NonDanceClip{name, std::move(loaded).value()};
}

}  // namespace

Result<std::vector<NonDanceClip>> load_non_dance_clips(const std::vector<std::string>& entries,
                                                       const std::string& data_dir) {
  std::vector<NonDanceClip> clips;
  if (entries.empty()) {
    // The default: the Bandai clips when the data folder has them.
    std::error_code ec;
    if (data_dir.empty() || !std::filesystem::exists(bandai_path(data_dir, kBandaiClips[0]), ec)) {
      return clips;
    }
    return load_non_dance_clips({"bandai"}, data_dir);
  }
  for (const std::string& entry : entries) {
    if (entry == "none") continue;
    if (entry == "bandai") {
      if (data_dir.empty()) {
        return Error{
            "--non-dance bandai: needs the data folder (--data-dir or $DUET_DATA_DIR; "
            "scripts/get-data.sh prints it)"};
      }
      for (const char* clip : kBandaiClips) {
        Result<NonDanceClip> loaded = load_clip(clip, bandai_path(data_dir, clip));
        if (!loaded) return loaded.error();
        clips.push_back(std::move(loaded).value());
      }
      continue;
    }
    // Named after the motion file (the last part of "skeleton.asf+motion.amc").
    const std::string motion = entry.substr(entry.rfind('+') + 1);
    Result<NonDanceClip> loaded = load_clip(std::filesystem::path(motion).stem().string(), entry);
    if (!loaded) return loaded.error();
    clips.push_back(std::move(loaded).value());
  }
  return clips;
}

}  // namespace duet::app
