// One motion as one command-line word: "take.bvh", or an ASF skeleton and an AMC motion joined by
// '+': "60.asf+60_01.amc" (either order). This lets every option that takes a BVH (--pair LEADER
// PARTNER, --input) take the CMU originals too without changing how many words it takes.
#pragma once

#include <string>
#include <vector>

#include "duet/base/result.h"

namespace duet {

// Splits a motion word into the paths load_motion() takes: {file.bvh} or {x.asf, y.amc}. A word
// that names an existing file is taken whole (a '+' inside a file name still works). Errors name
// the word and the part that is missing or wrong: a lone .asf or .amc ("needs its AMC/ASF:
// SKELETON.asf+MOTION.amc"), a part that does not exist, three parts, two parts that are not one
// .asf and one .amc.
Result<std::vector<std::string>> split_motion_argument(const std::string& word);

// The word back from the paths: "a.bvh" or "a.asf+b.amc".
std::string join_motion_argument(const std::vector<std::string>& paths);

}  // namespace duet
