#include "duet/io/atomic_write.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace duet {

Status write_file_atomically(const std::string& path, std::string_view content) {
  const std::string temporary = path + ".tmp";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    return Error{path + ": cannot write: " + std::strerror(errno)};
  }
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size();
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    std::remove(temporary.c_str());
    return Error{path + ": write failed: " + std::strerror(written ? errno : write_errno)};
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary.c_str());
    return Error{path + ": cannot rename the temporary file into place: " +
                 std::strerror(rename_errno)};
  }
  return Ok{};
}

}  // namespace duet
