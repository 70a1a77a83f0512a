// Test support: replaces the global operator new and delete of a test program with ones that
// count allocations while duet::test::g_counting is on, to show that a per-frame path allocates
// nothing after set-up (architecture.md: run time). Include it in exactly one source file of a
// test program: the replacements (and the test that the counter counts) are definitions.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

namespace duet::test {
inline std::atomic<bool> g_counting{false};
inline std::atomic<long> g_allocations{0};

inline void* counted_alloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
inline void* counted_aligned_alloc(std::size_t size, std::align_val_t align) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  const auto a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
}  // namespace duet::test

// The replacements pair malloc with free by design; GCC's mismatched-new-delete check, which
// sees both sides once inlined into a test, takes free here for a mismatch with new.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) { return duet::test::counted_alloc(size); }
void* operator new[](std::size_t size) { return duet::test::counted_alloc(size); }
void* operator new(std::size_t size, std::align_val_t align) {
  return duet::test::counted_aligned_alloc(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return duet::test::counted_aligned_alloc(size, align);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

// The counter itself counts (in every program that includes this): otherwise a test that
// expects no allocation could pass on a replacement not in use.
TEST(CountingNew, CountsAnAllocation) {
  duet::test::g_allocations = 0;
  duet::test::g_counting = true;
  auto allocated = std::make_unique<std::vector<int>>(16);
  duet::test::g_counting = false;
  EXPECT_GE(duet::test::g_allocations.load(), 1);
  EXPECT_EQ(allocated->size(), 16u);
}
