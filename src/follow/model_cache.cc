#include "duet/follow/model_cache.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <streambuf>
#include <vector>

#include "duet/base/content_hash.h"

namespace duet {
namespace {

constexpr char kMagic[8] = {'D', 'U', 'E', 'T', 'M', 'O', 'D', 'L'};
constexpr std::uint32_t kEndianMark = 0x01020304u;

struct Header {
  char magic[8];
  std::uint32_t version;
  std::uint32_t endian_mark;
  std::uint64_t feature_spec_hash;
  std::int32_t num_states;
  std::int32_t num_dims;
  std::int32_t velocity_dims;
  std::int32_t num_takes;
  double frame_rate_hz;
  std::uint64_t takes_offset, takes_bytes;
  std::uint64_t features_offset, features_bytes;
  std::uint64_t index_offset, index_bytes;
  std::uint64_t file_bytes;
  std::uint64_t checksum;  // of bytes [sizeof(Header), file_bytes)
};

// An istream over bytes in memory (the mapped index section), without a copy.
class MemoryBuffer : public std::streambuf {
 public:
  MemoryBuffer(const char* data, std::size_t size) {
    char* p = const_cast<char*>(data);  // read-only: only the get area is set
    setg(p, p, p + size);
  }
};

// A read-only memory map, unmapped on destruction.
class MappedFile {
 public:
  MappedFile() = default;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile() {
    if (data_ != nullptr) munmap(data_, size_);
  }
  // Empty string on success, else the reason.
  std::string open(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::strerror(errno);
    struct stat st {};
    if (fstat(fd, &st) != 0) {
      const std::string reason = std::strerror(errno);
      ::close(fd);
      return reason;
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
      void* p = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (p == MAP_FAILED) {
        const std::string reason = std::strerror(errno);
        ::close(fd);
        size_ = 0;
        return reason;
      }
      data_ = p;
    }
    ::close(fd);
    return {};
  }
  const unsigned char* data() const { return static_cast<const unsigned char*>(data_); }
  std::size_t size() const { return size_; }
  // Lets the kernel drop the pages read so far: they come back from the file when next read.
  // (Loading reads every byte once, for the checksum and the blocked copy; serving reads few.)
  void release_pages() const {
    if (data_ != nullptr) madvise(data_, size_, MADV_DONTNEED);
  }

 private:
  void* data_ = nullptr;
  std::size_t size_ = 0;
};

bool section_fits(std::uint64_t offset, std::uint64_t bytes, std::uint64_t file_bytes) {
  return offset >= sizeof(Header) && offset <= file_bytes && bytes <= file_bytes - offset;
}

}  // namespace

Status write_model_cache(const std::string& path, const TemplateModel& model,
                         const JumpCandidateIndex& index, std::uint64_t feature_spec_hash) {
  auto fail = [&](const std::string& what) { return make_error(path, 0, what); };
  std::ostringstream index_bytes(std::ios::binary);
  index.save(index_bytes);
  const std::string index_blob = std::move(index_bytes).str();

  std::vector<std::int32_t> takes;
  for (int k = 0; k < model.num_takes(); ++k) takes.push_back(model.take_begin(k));
  Header header{};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.version = kModelCacheVersion;
  header.endian_mark = kEndianMark;
  header.feature_spec_hash = feature_spec_hash;
  header.num_states = model.num_states();
  header.num_dims = model.num_dims();
  header.velocity_dims = model.velocity_dims();
  header.num_takes = model.num_takes();
  header.frame_rate_hz = model.frame_rate_hz();
  header.takes_offset = sizeof(Header);
  header.takes_bytes = takes.size() * sizeof(std::int32_t);
  header.features_offset = header.takes_offset + header.takes_bytes;
  header.features_bytes = static_cast<std::uint64_t>(model.features().size()) * sizeof(float);
  header.index_offset = header.features_offset + header.features_bytes;
  header.index_bytes = index_blob.size();
  header.file_bytes = header.index_offset + header.index_bytes;

  // The checksum runs over the sections in file order, so they are laid out in one buffer.
  std::vector<unsigned char> body(header.file_bytes - sizeof(Header));
  unsigned char* out = body.data();
  std::memcpy(out, takes.data(), header.takes_bytes);
  std::memcpy(out + header.takes_bytes, model.features().data(), header.features_bytes);
  std::memcpy(out + header.takes_bytes + header.features_bytes, index_blob.data(),
              index_blob.size());
  header.checksum = content_hash(body.data(), body.size());

  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) return fail("cannot write the model cache: " + std::string(std::strerror(errno)));
    file.write(reinterpret_cast<const char*>(&header), sizeof header);
    file.write(reinterpret_cast<const char*>(body.data()),
               static_cast<std::streamsize>(body.size()));
    if (!file.flush()) {
      std::remove(temporary.c_str());
      return fail("writing the model cache failed (disk full?)");
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temporary.c_str());
    return fail("cannot move the model cache into place: " + reason);
  }
  return Ok{};
}

Result<CachedModel> read_model_cache(const std::string& path, std::uint64_t feature_spec_hash) {
  auto fail = [&](const std::string& what) { return make_error(path, 0, what); };
  // Shared with the model, which keeps its row-major features in the map (build_shared).
  const auto mapped = std::make_shared<MappedFile>();
  const MappedFile& file = *mapped;
  if (const std::string reason = mapped->open(path); !reason.empty()) {
    return fail("cannot open the model cache: " + reason);
  }
  if (file.size() < sizeof(Header)) {
    return fail("not a Duet model cache: " + std::to_string(file.size()) +
                " bytes, shorter than its header (" + std::to_string(sizeof(Header)) + ")");
  }
  Header header;
  std::memcpy(&header, file.data(), sizeof header);
  if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
    return fail("not a Duet model cache (no DUETMODL magic at its start)");
  }
  if (header.version != kModelCacheVersion) {
    return fail("model cache format version " + std::to_string(header.version) +
                ", this build reads version " + std::to_string(kModelCacheVersion));
  }
  if (header.endian_mark != kEndianMark) {
    return fail("model cache written on a machine of another byte order");
  }
  if (header.feature_spec_hash != feature_spec_hash) {
    return fail("model cache made for another library or feature spec (key " +
                std::to_string(header.feature_spec_hash) + ", expected " +
                std::to_string(feature_spec_hash) + ")");
  }
  if (header.file_bytes != file.size()) {
    return fail("model cache truncated or extended: " + std::to_string(file.size()) +
                " bytes, its header says " + std::to_string(header.file_bytes));
  }
  const std::uint64_t size = file.size();
  const auto states = static_cast<std::uint64_t>(header.num_states);
  const auto dims = static_cast<std::uint64_t>(header.num_dims);
  if (header.num_states <= 0 || header.num_dims <= 0 || header.num_takes <= 0 ||
      header.velocity_dims < 0 || header.velocity_dims > header.num_dims ||
      header.takes_bytes != static_cast<std::uint64_t>(header.num_takes) * sizeof(std::int32_t) ||
      header.features_bytes != states * dims * sizeof(float) ||
      !section_fits(header.takes_offset, header.takes_bytes, size) ||
      !section_fits(header.features_offset, header.features_bytes, size) ||
      !section_fits(header.index_offset, header.index_bytes, size)) {
    return fail("model cache header inconsistent with its sizes (" +
                std::to_string(header.num_states) + " states x " + std::to_string(header.num_dims) +
                " dimensions, " + std::to_string(header.num_takes) + " takes in " +
                std::to_string(size) + " bytes)");
  }
  if (content_hash(file.data() + sizeof(Header), size - sizeof(Header)) != header.checksum) {
    return fail("model cache damaged (checksum mismatch)");
  }

  std::vector<int> takes(static_cast<std::size_t>(header.num_takes));
  std::memcpy(takes.data(), file.data() + header.takes_offset, header.takes_bytes);
  // The model reads its row-major features from the map (the few rows a beam needs per frame);
  // it copies them once into the blocked layout its SIMD kernel streams through. A map whose
  // features section is not aligned for floats (not one this build writes) is copied instead.
  const auto* features = reinterpret_cast<const float*>(file.data() + header.features_offset);
  const std::span<const float> feature_values(features, states * dims);
  Result<TemplateModel> model =
      reinterpret_cast<std::uintptr_t>(features) % alignof(float) == 0
          ? TemplateModel::build_shared(mapped, feature_values, header.num_states, header.num_dims,
                                        std::move(takes), header.frame_rate_hz,
                                        header.velocity_dims)
          : TemplateModel::build(std::vector<float>(feature_values.begin(), feature_values.end()),
                                 header.num_states, header.num_dims, std::move(takes),
                                 header.frame_rate_hz, header.velocity_dims);
  if (!model) return fail("model cache holds an invalid model: " + model.error().message);

  MemoryBuffer buffer(reinterpret_cast<const char*>(file.data() + header.index_offset),
                      header.index_bytes);
  std::istream in(&buffer);
  Result<JumpCandidateIndex> index =
      JumpCandidateIndex::load(in, header.num_states, header.num_dims - header.velocity_dims);
  if (!index) return fail("model cache: " + index.error().message);
  file.release_pages();
  return CachedModel{std::move(model).value(), std::move(index).value()};
}

Result<CachedModel> load_or_build_model_cache(const std::string& path,
                                              std::uint64_t feature_spec_hash,
                                              const std::function<Result<TemplateModel>()>& build,
                                              std::string* rebuilt_because) {
  Result<CachedModel> cached = read_model_cache(path, feature_spec_hash);
  if (cached) {
    if (rebuilt_because != nullptr) rebuilt_because->clear();
    return cached;
  }
  std::string reason = cached.error().message;
  Result<TemplateModel> model = build();
  if (!model) return model.error();
  Result<JumpCandidateIndex> index = JumpCandidateIndex::build(model.value());
  if (!index) return index.error();
  if (rebuilt_because != nullptr) *rebuilt_because = reason;
  if (Status written = write_model_cache(path, model.value(), index.value(), feature_spec_hash);
      !written.ok()) {
    if (rebuilt_because != nullptr) {
      *rebuilt_because += "; and the new cache could not be written: " + written.error().message;
    }
    return CachedModel{std::move(model).value(), std::move(index).value()};
  }
  // Served from the file just written, like the next start: its row-major features then stay
  // in the map instead of in memory (read_model_cache).
  Result<CachedModel> written = read_model_cache(path, feature_spec_hash);
  if (written) return written;
  return CachedModel{std::move(model).value(), std::move(index).value()};
}

}  // namespace duet
