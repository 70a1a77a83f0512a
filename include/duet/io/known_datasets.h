// Motion datasets whose files say something untrue about themselves. The CMU salsa takes
// (subjects 60 and 61) are the case in point: every BVH header says 120 fps, and ASF/AMC readers
// assume CMU's usual 120 Hz, but the takes are 60 Hz (data README, "Frame rate"). Library files
// and directory recognition fix the rate once; `duet inspect` warns with
// known_dataset_rate_warning().
#pragma once

#include <string>
#include <vector>

namespace duet {

struct KnownDataset {
  std::string name;         // "cmu-salsa"
  std::string description;  // one line for messages
  // CMU subject numbers of the two dancers; files are named SUBJECT_TRIAL*.bvh / .amc and
  // SUBJECT.asf, which is how a file is recognised as part of the dataset.
  std::string leader_subject;
  std::string partner_subject;
  double frame_rate_hz = 0.0;  // the true capture rate
  std::string rate_note;       // why, for the warning
};

const std::vector<KnownDataset>& known_datasets();

// The known dataset a motion file belongs to, by its file name (60_03_scaled.bvh, 61_01.amc,
// 60.asf), or nullptr. Only the name is looked at: CMU subject numbers are unique within CMU's
// database, and other datasets are not CMU's.
const KnownDataset* find_known_dataset(const std::string& motion_path);

// For `duet inspect`: a warning when `file_fps` (the rate in a BVH header, or the rate an AMC was
// read at) disagrees with the true rate of the known dataset the file belongs to, such as
// "60_01_scaled.bvh: the header says 120 fps but the CMU salsa takes are 60 Hz (...); pass
// --fps 60". Empty when the file is not from a known dataset or the rates agree (within 0.5%).
std::string known_dataset_rate_warning(const std::string& motion_path, double file_fps);

}  // namespace duet
