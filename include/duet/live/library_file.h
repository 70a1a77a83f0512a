// A library of duets described once, in a file, instead of --pair options typed by hand
// (docs/file-formats.md, "Library files"): a TOML file with the pairs, the frame rate, units and
// the dancers' names; or a directory holding such a file or the pair files themselves.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/live/duet_library.h"

namespace duet {

struct LibrarySpec {
  std::string source;  // the library file read, or the directory whose pairs were recognised
  std::string name;
  std::string description;
  std::string leader_name;   // who the leader is ("subject 60 (male)"), for messages
  std::string partner_name;
  std::optional<double> frame_rate;       // `fps`: overrides the files' headers
  std::optional<double> metres_per_unit;  // `scale`: overrides the skeleton conventions' units
  bool trim_to_shorter = false;           // `trim`
  std::vector<PairFiles> pairs;           // paths resolved, every file checked to exist
  std::vector<std::string> notes;         // for a recognised directory: what was guessed
};

// The data directory that ${data} in a library file's paths stands for: `data_dir` when not
// empty, else $DUET_DATA_DIR, else empty.
std::string library_data_dir(const std::string& data_dir);

// Reads a library file (TOML). Relative paths start at `root` (default: the file's directory; a
// relative root starts there too); "${data}" in a path is library_data_dir(data_dir). Errors name
// the file, the line and the key: unknown keys, wrong types, missing pair files, ${data} with no
// data directory, TOML syntax.
Result<LibrarySpec> read_library_file(const std::string& path, const std::string& data_dir = {});

// A directory: its library file (library.toml, or its only *.toml), else the duets recognised
// from CMU-style file names under it (up to 3 levels): SUBJECT_TRIAL*.bvh, or SUBJECT.asf with
// SUBJECT_TRIAL.amc, of exactly two subjects; a trial with both dancers is a pair, BVH preferred
// over ASF+AMC. The leader is the known dataset's (duet/io/known_datasets.h) or, failing that,
// the lower subject number (said in `notes`); a known dataset also sets the frame rate.
Result<LibrarySpec> read_library_dir(const std::string& dir, const std::string& data_dir = {});

// read_library_file or read_library_dir, whichever `file_or_dir` is.
Result<LibrarySpec> read_library(const std::string& file_or_dir, const std::string& data_dir = {});

}  // namespace duet
