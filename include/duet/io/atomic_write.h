// Writing a whole file so that readers never see half of it: write "<path>.tmp", flush, rename.
#pragma once

#include <string>
#include <string_view>

#include "duet/base/result.h"

namespace duet {

// On failure the temporary file is removed and the error names `path` and the reason. A `path`
// that exists and is no regular file (/dev/null, /dev/stdout, a FIFO) is written directly: a
// rename would replace the device itself (as root, `-o /dev/null` turned /dev/null into a file).
Status write_file_atomically(const std::string& path, std::string_view content);

}  // namespace duet
