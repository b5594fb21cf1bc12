#pragma once
/// An allocator for the per-link buffers of big trees: buffers of 2 MiB and more are placed on
/// 2 MiB boundaries and, on Linux, marked for transparent huge pages (madvise MADV_HUGEPAGE). A
/// pass over a 10,000-link chain touches about 7 MB of link data; with 4 KiB pages every link
/// costs TLB misses, which a virtual machine's nested page walk makes expensive (measured: the
/// centre of mass of a 10,000-link chain 51 -> 38 ns per link, inverse dynamics 130 -> 88 ns per
/// link, with 100 links at 23 and 49). Smaller buffers come from operator new as usual. The
/// allocation happens when the model or its data is built, never per tick.
#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace mechbal::detail {

template <class T>
struct LargeBufferAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;

  LargeBufferAllocator() noexcept = default;
  template <class U>
  LargeBufferAllocator(const LargeBufferAllocator<U>&) noexcept {}  // NOLINT: rebinding

  static bool large(std::size_t n) noexcept { return n * sizeof(T) >= kHugePage; }

  T* allocate(std::size_t n) {
    if (!large(n)) return static_cast<T*>(::operator new(n * sizeof(T)));
    const std::size_t bytes = (n * sizeof(T) + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, bytes);
    if (p == nullptr) {  // as operator new: bad_alloc, or abort in a build without exceptions
#if defined(__cpp_exceptions)
      throw std::bad_alloc();
#else
      std::abort();
#endif
    }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    (void)madvise(p, bytes, MADV_HUGEPAGE);  // a hint: without huge pages the buffer still works
#endif
    return static_cast<T*>(p);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (large(n)) {
      std::free(p);
    } else {
      ::operator delete(p);
    }
  }

  template <class U>
  bool operator==(const LargeBufferAllocator<U>&) const noexcept { return true; }
  template <class U>
  bool operator!=(const LargeBufferAllocator<U>&) const noexcept { return false; }
};

}  // namespace mechbal::detail
