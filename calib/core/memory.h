#pragma once
// Large arrays backed by transparent huge pages. Filling a fresh array takes a page fault every
// 4 kB; on a virtual machine each costs microseconds, and for the million-pose arrays of a
// trajectory benchmark they were a third of the run (doc/performance.md). Debian's kernels give
// huge pages (2 MB) to regions that ask for them (THP "madvise" mode), 512 times fewer faults.
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

namespace rigcal {

// Asks for huge pages on the 2 MB pages inside [p, p + bytes). Nothing for regions under 4 MB,
// or where the kernel has no transparent huge pages; never an error.
void advise_huge_pages(const void* p, size_t bytes);

// v.reserve(n) with the new storage advised as above (before anything touches it).
template <class T, class Allocator>
void reserve_huge(std::vector<T, Allocator>& v, size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
}

// Writes a byte in every 4 kB page of [p, p + bytes), from all cores. The kernel zeroes a fresh
// page at its first touch (several ms a MB on a virtual machine): done here in parallel, not by
// the one thread that then constructs a vector's elements.
void touch_pages_in_parallel(void* p, size_t bytes);

// reserve_huge, and the new storage's pages touched in parallel: for a vector one thread will
// resize or fill.
template <class T, class Allocator>
void reserve_huge_touched(std::vector<T, Allocator>& v, size_t n) {
  if (n <= v.capacity()) return;
  reserve_huge(v, n);
  touch_pages_in_parallel(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
}

// An allocator whose resize leaves new elements of a trivial type uninitialised: the pages of a
// large array are then first touched, and zeroed by the kernel, by the threads that fill it in
// parallel, not by one thread's resize before them.
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) {}
  template <class U>
  void construct(U* p) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using UninitialisedVector = std::vector<T, UninitialisedAllocator<T>>;

}  // namespace rigcal
