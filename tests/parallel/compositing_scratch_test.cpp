// The buffers a thread's composites reuse (parallel/compositing_scratch.hpp): handed back, a
// buffer comes back empty with its capacity, on the same thread only, and no more than the cap
// is kept.
#include "parallel/compositing_scratch.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>
#include <utility>
#include <vector>

namespace insitu::detail {
namespace {

// Each on a thread of its own: what earlier tests on the main thread kept stays out of it.
TEST(CompositingScratch, ABufferHandedBackComesBackEmptyWithItsCapacity) {
    std::thread([] {
        Bytes bytes = borrow_bytes();
        bytes.assign(1000, 7);
        const std::uint8_t* memory = bytes.data();
        give_back(std::move(bytes));
        const Bytes again = borrow_bytes();
        EXPECT_TRUE(again.empty());
        EXPECT_GE(again.capacity(), 1000u);
        EXPECT_EQ(again.data(), memory);  // the same memory, not a fresh allocation
        std::vector<float> floats = borrow_floats();
        floats.assign(500, 1.0f);
        give_back(std::move(floats));
        std::thread([] { EXPECT_EQ(borrow_floats().capacity(), 0u); }).join();  // another thread's
        EXPECT_GE(borrow_floats().capacity(), 500u);
    }).join();
}

TEST(CompositingScratch, KeepsNoMoreThanTheCap) {
    std::thread([] {
        Bytes big;
        big.reserve(kKeptBytes + 1);
        give_back(std::move(big));
        EXPECT_EQ(borrow_bytes().capacity(), 0u);  // over the cap: freed
        std::vector<Bytes> halves(3);
        for (Bytes& half : halves) half.reserve(kKeptBytes / 2);
        give_back(halves);
        EXPECT_GT(borrow_bytes().capacity(), 0u);  // two were kept, the third freed
        EXPECT_GT(borrow_bytes().capacity(), 0u);
        EXPECT_EQ(borrow_bytes().capacity(), 0u);
    }).join();
}

}  // namespace
}  // namespace insitu::detail
