// Counts every heap allocation of the test executable that includes it (include it in exactly one
// source file), so a test can assert that a simulation step allocates nothing: every global
// operator new, and (outside sanitizer builds, where ASan owns malloc) the C allocation functions
// malloc, calloc, realloc, aligned_alloc, posix_memalign and memalign, through which Eigen
// allocates its dynamic temporaries. Allocation and release go through out-of-line functions so
// the compiler does not pair an inlined `new` with `free` (GCC's -Wmismatched-new-delete).
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>
#include <malloc.h>
#include <stdlib.h>

#if defined(__SANITIZE_ADDRESS__)
#define MANISOFT_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MANISOFT_TEST_SANITIZED 1
#endif
#endif

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

#if !defined(MANISOFT_TEST_SANITIZED)
// glibc's allocator entry points behind the public names; interposing the public names counts
// every C allocation of the process.
extern "C" {
void* __libc_malloc(std::size_t) noexcept;
void* __libc_calloc(std::size_t, std::size_t) noexcept;
void* __libc_realloc(void*, std::size_t) noexcept;
void* __libc_memalign(std::size_t, std::size_t) noexcept;
void* malloc(std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  return __libc_realloc(p, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  return __libc_memalign(alignment, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  ++manisoft_test::allocation_count;
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}
namespace manisoft_test {
inline constexpr bool counts_malloc = true;
}
#else
namespace manisoft_test {
inline constexpr bool counts_malloc = false;  ///< under ASan only operator new is counted
}
#endif
