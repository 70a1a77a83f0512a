// Writing a whole file so that readers never see half of it: write "<path>.tmp", flush, rename.
#pragma once

#include <string>
#include <string_view>

#include "duet/base/result.h"

namespace duet {

// On failure the temporary file is removed and the error names `path` and the reason.
Status write_file_atomically(const std::string& path, std::string_view content);

}  // namespace duet
