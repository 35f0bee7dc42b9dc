#include "gvins/base/heap_pages.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace gvins {

void keepHeapPages() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace gvins
