// Process-wide allocator setting for the command-line tools.
#pragma once

namespace gvins {

/// Keeps freed heap memory in the process. With glibc's default thresholds, blocks of 128 kB and
/// more are mmap()ed and unmapped on free, and the top of the heap is trimmed with brk() after
/// frees, so a loop that allocates and frees a few hundred kB per step (filter copies, QR
/// buffers, the readers' buffers) faults the same pages in again every step: a third of
/// gvins-rtk's CPU time in instantaneous mode went to the kernel. Fixed thresholds (mallopt(3):
/// M_MMAP_THRESHOLD 32 MB, M_TRIM_THRESHOLD 256 MB) keep the pages; peak memory is unchanged.
/// Does nothing on other C libraries. Call once at the start of main().
void keepHeapPages();

}  // namespace gvins
