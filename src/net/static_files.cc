#include "duet/net/static_files.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <system_error>
#include <utility>

namespace duet::net {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxTargetLength = 2048;

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Decodes %XX escapes; false on a malformed escape or a decoded NUL.
bool percent_decode(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    char c = in[i];
    if (c == '%') {
      if (i + 2 >= in.size()) return false;
      const int hi = hex_value(in[i + 1]);
      const int lo = hex_value(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      c = static_cast<char>(hi * 16 + lo);
      i += 2;
    }
    if (c == '\0') return false;
    out += c;
  }
  return true;
}

bool is_within(const fs::path& root, const fs::path& path) {
  const auto [root_end, unused] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  return root_end == root.end();
}

}  // namespace

std::optional<fs::path> canonical_web_root(const fs::path& dir) {
  std::error_code ec;
  fs::path root = fs::canonical(dir, ec);
  if (ec || !fs::is_directory(root, ec) || ec) return std::nullopt;
  return root;
}

StaticFile find_static_file(const fs::path& web_root, std::string_view target) {
  StaticFile result;
  result.status = StaticLookup::kBadTarget;
  if (target.size() > kMaxTargetLength) return result;
  target = target.substr(0, target.find_first_of("?#"));
  std::string decoded;
  if (target.empty() || target.front() != '/' || !percent_decode(target, decoded)) return result;
  if (decoded.find('\\') != std::string::npos) return result;
  // Refuse any ".." segment (and "." ones, which no link of ours has), before touching the disk.
  std::string relative;
  std::size_t pos = 0;
  while (pos < decoded.size()) {
    const std::size_t slash = decoded.find('/', pos);
    const std::string_view segment = std::string_view(decoded).substr(
        pos, slash == std::string::npos ? std::string::npos : slash - pos);
    pos = slash == std::string::npos ? decoded.size() : slash + 1;
    if (segment.empty()) continue;
    if (segment == ".." || segment == ".") return result;
    if (!relative.empty()) relative += '/';
    relative += segment;
  }

  result.status = StaticLookup::kNotFound;
  fs::path path = relative.empty() ? web_root : web_root / relative;
  std::error_code ec;
  if (fs::is_directory(path, ec)) path /= "index.html";
  const fs::path canonical = fs::canonical(path, ec);
  if (ec || !is_within(web_root, canonical) || !fs::is_regular_file(canonical, ec) || ec) {
    return result;
  }
  result.status = StaticLookup::kFound;
  result.path = canonical;
  return result;
}

std::string_view content_type_for(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 22> kTypes = {{
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/markdown; charset=utf-8"},
      {".bvh", "text/plain; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".gif", "image/gif"},
      {".webp", "image/webp"},
      {".ico", "image/x-icon"},
      {".wasm", "application/wasm"},
      {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},
      {".woff2", "font/woff2"},
      {".woff", "font/woff"},
  }};
  for (const auto& [extension, type] : kTypes) {
    if (ext == extension) return type;
  }
  return "application/octet-stream";
}

}  // namespace duet::net
