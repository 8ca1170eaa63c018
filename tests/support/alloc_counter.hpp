#pragma once

#include <cstdint>

// Counts heap allocations made by any thread of the test executable, so a test can prove that a
// scope (a frame of the pipeline, the firmware loop's steady state) never touches the heap.
//
// Linking smx_alloc_counter replaces the global operator new/delete and malloc, calloc, realloc,
// aligned_alloc, posix_memalign and memalign. Under ASan/UBSan the sanitizer owns those symbols,
// so the counter installs the sanitizer's allocator hooks instead, which see every allocation
// (operator new included).
namespace smx::test {

// Frames a steady-state test of the firmware loop runs. Under AddressSanitizer each frame costs
// some twenty times as much, and a quarter of the frames runs the same loop's code.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kSteadyStateFrames = 25;
#else
inline constexpr int kSteadyStateFrames = 100;
#endif

// Allocations since the process started (all threads).
[[nodiscard]] std::uint64_t allocationsSoFar();
[[nodiscard]] std::uint64_t bytesAllocatedSoFar();

// Counts what happens between construction and each query.
class AllocationCounter {
 public:
  AllocationCounter() : allocations_(allocationsSoFar()), bytes_(bytesAllocatedSoFar()) {}
  [[nodiscard]] std::uint64_t allocations() const { return allocationsSoFar() - allocations_; }
  [[nodiscard]] std::uint64_t bytes() const { return bytesAllocatedSoFar() - bytes_; }

 private:
  std::uint64_t allocations_;
  std::uint64_t bytes_;
};

}  // namespace smx::test
