#include "duet/io/atomic_write.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace duet {

namespace {

// Devices and pipes cannot be replaced by a rename, and need not be: nobody reads them as a file.
Status write_directly(const std::string& path, std::string_view content) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return Error{path + ": cannot write: " + std::strerror(errno)};
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size();
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written) {
    return Error{path + ": write failed: " + std::strerror(written ? errno : write_errno)};
  }
  return Ok{};
}

}  // namespace

Status write_file_atomically(const std::string& path, std::string_view content) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::is_directory(status)) return Error{path + ": is a directory"};
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    return write_directly(path, content);
  }
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
