#include "rigcal/core/memory.h"

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>

namespace rigcal {

void advise_huge_pages(const void* p, size_t bytes) {
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  if (p == nullptr || bytes < 2 * kHuge) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

void touch_pages_in_parallel(void* p, size_t bytes) {
  constexpr size_t kPage = 4096;
  auto* bytes_at = static_cast<volatile unsigned char*>(p);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, bytes, size_t{2} << 20), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); i += kPage) bytes_at[i] = 0;
  });
}

}  // namespace rigcal
