// Replaces every global operator new/delete of the test executable that includes it (include it
// in exactly one source file) with versions that count allocations, so a test can assert that a
// simulation step allocates nothing. Allocation and release go through out-of-line functions so
// the compiler does not pair an inlined `new` with `free` (GCC's -Wmismatched-new-delete).
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace manisoft_test {
inline std::atomic<long> allocation_count{0};
[[gnu::noinline]] inline void* counted_allocation(std::size_t size) noexcept {
  ++allocation_count;
  return std::malloc(size ? size : 1);
}
[[gnu::noinline]] inline void counted_release(void* p) noexcept { std::free(p); }
}  // namespace manisoft_test

void* operator new(std::size_t size) {
  if (void* p = manisoft_test::counted_allocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = manisoft_test::counted_allocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return manisoft_test::counted_allocation(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return manisoft_test::counted_allocation(size); }
void operator delete(void* p) noexcept { manisoft_test::counted_release(p); }
void operator delete[](void* p) noexcept { manisoft_test::counted_release(p); }
void operator delete(void* p, std::size_t) noexcept { manisoft_test::counted_release(p); }
void operator delete[](void* p, std::size_t) noexcept { manisoft_test::counted_release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { manisoft_test::counted_release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { manisoft_test::counted_release(p); }
