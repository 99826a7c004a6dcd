#pragma once

#include <cstddef>

namespace csgrt {

/// The size of a transparent huge page on x86-64 and the granule of huge_page_block.
inline constexpr std::size_t kHugePageBytes = std::size_t(1) << 21;

/// `bytes` rounded up to whole huge pages.
constexpr std::size_t huge_page_block_size(std::size_t bytes) {
    return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

/// A block of huge_page_block_size(bytes) bytes aligned to 2 MiB, the kernel asked (madvise)
/// to back it with transparent huge pages: a large buffer written once from start to end (a
/// batch's results, which Python reuses: python/src/arrays.cpp) then takes one page fault per 2 MiB
/// instead of one per 4 KiB. Advice only: where huge pages are off, 4 KiB pages serve. Throws
/// std::bad_alloc; freed with free_huge_page_block.
void* allocate_huge_page_block(std::size_t bytes);
void free_huge_page_block(void* block);

}  // namespace csgrt
