#include "csgrt/core/huge_pages.h"

#include <sys/mman.h>

#include <cstdlib>
#include <new>

namespace csgrt {

void* allocate_huge_page_block(std::size_t bytes) {
    const std::size_t size = huge_page_block_size(bytes);
    // aligned_alloc wants a multiple of the alignment.
    void* block = std::aligned_alloc(kHugePageBytes, size);
    if (block == nullptr) throw std::bad_alloc();
    static_cast<void>(::madvise(block, size, MADV_HUGEPAGE));
    return block;
}

void free_huge_page_block(void* block) {
    std::free(block);
}

}  // namespace csgrt
