#include "csgrt/core/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

namespace csgrt {
namespace {

TEST(HugePages, BlocksAreWholeAlignedHugePages) {
    EXPECT_EQ(huge_page_block_size(1), kHugePageBytes);
    EXPECT_EQ(huge_page_block_size(kHugePageBytes), kHugePageBytes);
    EXPECT_EQ(huge_page_block_size(kHugePageBytes + 1), 2 * kHugePageBytes);
    for (const std::size_t bytes : {std::size_t{1}, kHugePageBytes + 3, 3 * kHugePageBytes}) {
        void* block = allocate_huge_page_block(bytes);
        ASSERT_NE(block, nullptr);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block) % kHugePageBytes, 0u);
        // All of the rounded size is the caller's: written and read back to its last byte.
        const std::size_t size = huge_page_block_size(bytes);
        std::memset(block, 0xA5, size);
        EXPECT_EQ(static_cast<unsigned char*>(block)[size - 1], 0xA5);
        free_huge_page_block(block);
    }
}

}  // namespace
}  // namespace csgrt
