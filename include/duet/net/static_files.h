// Serving the viewer's static files: mapping a request target to a file inside the web directory
// (never outside it) and a file name to its content type.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace duet::net {

enum class StaticLookup {
  kFound,
  kBadTarget,  // not a clean absolute path: "..", NUL, backslash, bad %-escape, too long
  kNotFound,   // no such file (or a directory without index.html, or a link leading outside)
};

struct StaticFile {
  StaticLookup status = StaticLookup::kNotFound;
  std::filesystem::path path;  // when found: the canonical path of a regular file
};

// `web_root` must be canonical (see canonical_web_root). `target` is the request target
// ("/index.html?v=2"): the query and fragment are ignored, %-escapes decoded, "/" and directories
// map to index.html. Any ".." segment is refused outright; symbolic links are followed but the
// file they lead to must lie inside web_root.
StaticFile find_static_file(const std::filesystem::path& web_root, std::string_view target);

// The canonical form of a web directory, or nullopt when it does not exist or is not a directory.
std::optional<std::filesystem::path> canonical_web_root(const std::filesystem::path& dir);

// "text/html; charset=utf-8", "text/javascript; charset=utf-8", ..., by extension
// (case-insensitive); "application/octet-stream" for unknown ones.
std::string_view content_type_for(const std::filesystem::path& path);

}  // namespace duet::net
