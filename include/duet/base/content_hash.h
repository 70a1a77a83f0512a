// A fast 64-bit hash of bytes, for checksums and cache keys (the model cache, the grown
// library's key). 64-bit words mixed FNV-style (the tail byte-wise): ~5 GB/s, enough to catch
// damage or a changed input; not a defence against a crafted file.
#pragma once

#include <cstddef>
#include <cstdint>

namespace duet {

inline constexpr std::uint64_t kContentHashSeed = 0xcbf29ce484222325ull;

// Hashes size bytes at data, continuing from seed (pass a previous result to hash several
// pieces as one).
std::uint64_t content_hash(const void* data, std::size_t size,
                           std::uint64_t seed = kContentHashSeed) noexcept;

}  // namespace duet
