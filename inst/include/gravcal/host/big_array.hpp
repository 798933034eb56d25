// Large arrays of doubles whose memory the system may back with huge pages.
//
// A block of GGIR's reading is hundreds of MB written once from fresh
// memory: with 4 KB pages, each page's first write is a page fault (about
// 75,000 for a 36-hour block of three axes at 100 Hz), and on a virtual
// machine a fault costs several microseconds (measured in a profile of
// g.part1(): a sixth of the process's CPU in the fault handler, most of it
// under the decoder's writes into the block). An array of at least
// kHugeFrom bytes is aligned to 2 MB and advised as huge-page memory
// (Linux's madvise(MADV_HUGEPAGE); it takes effect where transparent huge
// pages are "madvise" or "always", and changes nothing where they are
// "never"), so that a fault backs 2 MB at a time. Pages never written are
// never backed, with or without the advice. Elsewhere (no madvise) the
// array is plain allocated memory. The values are the same either way:
// only where the memory comes from changes.
#ifndef GRAVCAL_HOST_BIG_ARRAY_HPP
#define GRAVCAL_HOST_BIG_ARRAY_HPP

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace gravcal {

struct BigArrayFree {
  void operator()(double* p) const { std::free(p); }
};
using BigArray = std::unique_ptr<double[], BigArrayFree>;

// (below this, the fault count is small and the 2 MB alignment not worth it)
constexpr std::size_t kHugeFrom = std::size_t{4} << 20;

// `bytes` (at least 1) of memory for std::free(), uninitialised; throws
// std::bad_alloc when there is none.
inline void* big_bytes(std::size_t bytes) {
  if (bytes == 0) bytes = 1;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes >= kHugeFrom) {
    constexpr std::size_t kHuge = std::size_t{2} << 20;
    const std::size_t whole = (bytes + kHuge - 1) / kHuge * kHuge;
    void* p = nullptr;
    if (posix_memalign(&p, kHuge, whole) != 0 || p == nullptr) throw std::bad_alloc();
    (void)madvise(p, whole, MADV_HUGEPAGE);  // advice: where refused, 4 KB pages as before
    return p;
  }
#endif
  void* p = std::malloc(bytes);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

// An array of n doubles (at least one), uninitialised.
inline BigArray big_array(std::size_t n) {
  if (n > static_cast<std::size_t>(-1) / sizeof(double) / 2) throw std::bad_alloc();
  return BigArray(static_cast<double*>(big_bytes(n * sizeof(double))));
}

// The same memory for a std::vector: std::vector<T, BigAllocator<T>>
// (BigVector for doubles), its large buffers advised as huge-page memory.
template <class T>
struct BigAllocator {
  using value_type = T;
  BigAllocator() = default;
  template <class U>
  BigAllocator(const BigAllocator<U>&) {}  // NOLINT(google-explicit-constructor): std's allocator rules
  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T) / 2) throw std::bad_alloc();
    return static_cast<T*>(big_bytes(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  template <class U>
  bool operator==(const BigAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const BigAllocator<U>&) const { return false; }
};
using BigVector = std::vector<double, BigAllocator<double>>;

}  // namespace gravcal

#endif  // GRAVCAL_HOST_BIG_ARRAY_HPP
