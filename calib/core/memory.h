#pragma once
// Large arrays backed by transparent huge pages. Filling a fresh array takes a page fault every
// 4 kB; on a virtual machine each costs microseconds, and for the million-pose arrays of a
// trajectory benchmark they were a third of the run (doc/performance.md). Debian's kernels give
// huge pages (2 MB) to regions that ask for them (THP "madvise" mode), 512 times fewer faults.
#include <cstddef>
#include <vector>

namespace rigcal {

// Asks for huge pages on the 2 MB pages inside [p, p + bytes). Nothing for regions under 4 MB,
// or where the kernel has no transparent huge pages; never an error.
void advise_huge_pages(const void* p, size_t bytes);

// v.reserve(n) with the new storage advised as above (before anything touches it).
template <class T>
void reserve_huge(std::vector<T>& v, size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
}

}  // namespace rigcal
