// Private file helper for the readers in src/io: read a whole file at once. (Writing goes through
// duet/io/atomic_write.h.)
#pragma once

#include <string>
#include <string_view>

#include "duet/base/result.h"

namespace duet::io_internal {

// Reads the whole file into memory in one call (no per-line or per-number stream I/O).
// Errors name the path: "walk.bvh: cannot open: No such file or directory".
Result<std::string> read_text_file(const std::string& path);

}  // namespace duet::io_internal
