// The library model cache file: a library's template model (features, takes, frame rate) and the
// beam follower's jump candidate index, written once so that a big library starts without
// rebuilding them (issue 13: 1M states in well under a second). Read through a memory map.
//
// Layout (native-endian; docs/file-formats.md "Model cache"): a fixed header with the magic
// "DUETMODL", the format version, an endianness mark, the hash of the feature spec the features
// were computed with, the model's sizes, the offset and size of each section and a checksum of
// everything after the header; then the take starts, the features (row-major float32) and the
// index. A cache that is truncated, foreign (another magic, version, byte order or feature spec)
// or damaged (checksum) is rejected with an error that names the file and what is wrong;
// load_or_build_model_cache then rebuilds and rewrites it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "duet/base/result.h"
#include "duet/follow/jump_candidates.h"
#include "duet/follow/template_model.h"

namespace duet {

inline constexpr std::uint32_t kModelCacheVersion = 2;  // 2: features at half precision

struct CachedModel {
  TemplateModel model;
  JumpCandidateIndex index;
};

// Writes model and index to path (through a temporary file renamed into place, so a reader never
// sees half a cache). feature_spec_hash identifies how the features were made.
Status write_model_cache(const std::string& path, const TemplateModel& model,
                         const JumpCandidateIndex& index, std::uint64_t feature_spec_hash);

// Reads a cache written by write_model_cache for the same feature_spec_hash.
Result<CachedModel> read_model_cache(const std::string& path, std::uint64_t feature_spec_hash);

// read_model_cache, or when that fails: build() the model, build its index, write the cache and
// return them. *rebuilt_because (if given) receives why the cache was not used (empty when it
// was). An error only when building fails; a cache that cannot be written is reported in
// *rebuilt_because and the built model returned.
Result<CachedModel> load_or_build_model_cache(const std::string& path,
                                              std::uint64_t feature_spec_hash,
                                              const std::function<Result<TemplateModel>()>& build,
                                              std::string* rebuilt_because = nullptr);

}  // namespace duet
