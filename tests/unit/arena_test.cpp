#include "smx/algo/arena.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "alloc_counter.hpp"

namespace smx::algo {
namespace {

bool aligned(const void* p, std::size_t a) {
  return reinterpret_cast<std::uintptr_t>(p) % a == 0;
}

TEST(Arena, CarvesAlignedDisjointBlocksFromTheCallersBuffer) {
  alignas(64) std::array<std::byte, 1024> buffer{};
  Arena arena(std::span<std::byte>(buffer).subspan(1));  // deliberately misaligned start
  auto bytes = arena.allocate<std::uint8_t>(3);
  auto words = arena.allocate<std::int32_t>(5);
  auto wide = arena.allocate<std::int64_t>(2);
  ASSERT_TRUE(bytes && words && wide);
  EXPECT_TRUE(aligned(words->data(), alignof(std::int32_t)));
  EXPECT_TRUE(aligned(wide->data(), alignof(std::int64_t)));
  // Inside the buffer and not overlapping.
  const auto* begin = buffer.data();
  const auto* end = buffer.data() + buffer.size();
  EXPECT_GE(reinterpret_cast<const std::byte*>(bytes->data()), begin + 1);
  EXPECT_GE(reinterpret_cast<const std::byte*>(words->data()),
            reinterpret_cast<const std::byte*>(bytes->data() + 3));
  EXPECT_GE(reinterpret_cast<const std::byte*>(wide->data()),
            reinterpret_cast<const std::byte*>(words->data() + 5));
  EXPECT_LE(reinterpret_cast<const std::byte*>(wide->data() + 2), end);
}

TEST(Arena, ImagesHaveAlignedPaddedRows) {
  alignas(16) std::array<std::byte, 4096> buffer{};
  Arena arena(buffer);
  auto rgb = arena.allocateImage<Rgb8>(7, 5);
  auto s16 = arena.allocateImage<std::int16_t>(9, 3);
  ASSERT_TRUE(rgb && s16);
  EXPECT_EQ(rgb->strideBytes(), 32);  // 21 bytes rounded up to 16
  EXPECT_EQ(s16->strideBytes(), 32);  // 18 bytes rounded up to 16
  for (int y = 0; y < 5; ++y) {
    EXPECT_TRUE(aligned(rgb->rowPtr(y), Arena::kRowAlignBytes));
  }
  EXPECT_EQ(arena.used(), 5U * 32U + 3U * 32U);
}

TEST(Arena, ReportsHighWaterAcrossRewinds) {
  alignas(16) std::array<std::byte, 1000> buffer{};
  Arena arena(buffer);
  ASSERT_TRUE(arena.allocate<std::int32_t>(10));  // 40 bytes of init-time state
  const auto frameStart = arena.mark();
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(arena.allocate<std::int32_t>(static_cast<std::size_t>(frame + 1) * 50));
    arena.rewind(frameStart);
    EXPECT_EQ(arena.used(), 40U);
  }
  EXPECT_EQ(arena.highWater(), 40U + 150U * 4U);
  EXPECT_EQ(arena.capacity(), 1000U);
}

TEST(Arena, ExhaustionAndOverflowAreErrorsAndLeaveTheArenaUsable) {
  alignas(16) std::array<std::byte, 100> buffer{};
  Arena arena(buffer);
  ASSERT_TRUE(arena.allocate<std::byte>(60));
  const auto tooBig = arena.allocate<std::byte>(41);
  ASSERT_FALSE(tooBig.has_value());
  EXPECT_EQ(tooBig.error().code, Errc::kOutOfMemory);
  EXPECT_EQ(arena.used(), 60U);
  EXPECT_TRUE(arena.allocate<std::byte>(40));
  EXPECT_FALSE(arena.allocate<std::int64_t>(SIZE_MAX / 4));
  EXPECT_FALSE(arena.allocateImage<std::int32_t>(1 << 30, 1 << 30));
  EXPECT_FALSE(arena.allocateBytes(1, 3));  // alignment not a power of two
}

TEST(Arena, NeverTouchesTheHeap) {
  alignas(16) std::array<std::byte, 4096> buffer{};
  test::AllocationCounter counter;
  Arena arena(buffer);
  const auto mark = arena.mark();
  for (int i = 0; i < 100; ++i) {
    (void)arena.allocateImage<std::int16_t>(31, 17);
    (void)arena.allocate<std::byte>(5000);  // fails without allocating
    arena.rewind(mark);
  }
  EXPECT_EQ(counter.allocations(), 0U);
}

}  // namespace
}  // namespace smx::algo
