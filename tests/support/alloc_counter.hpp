#pragma once

#include <cstdint>

// Counts heap allocations made by any thread of the test executable, so a test can prove that a
// scope (a frame of the pipeline, 100 frames of the firmware loop) never touches the heap.
//
// Linking smx_alloc_counter replaces the global operator new/delete and malloc, calloc, realloc,
// aligned_alloc, posix_memalign and memalign. Under ASan/UBSan the sanitizer owns those symbols,
// so the counter installs the sanitizer's allocator hooks instead, which see every allocation
// (operator new included).
namespace smx::test {

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
