#include "alloc_counter.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace smx::test {
namespace {

// Keeps the optimiser from eliding an allocation whose result is never used (allowed for new).
void escape(void* p) {
  asm volatile("" : : "g"(p) : "memory");
}

TEST(AllocCounter, CountsNothingWhenNothingAllocates) {
  AllocationCounter counter;
  int sum = 0;
  for (int i = 0; i < 1000; ++i) {
    sum += i;
  }
  escape(&sum);
  EXPECT_EQ(counter.allocations(), 0U);
  EXPECT_EQ(counter.bytes(), 0U);
}

TEST(AllocCounter, CountsOperatorNewInEveryForm) {
  AllocationCounter counter;
  auto* one = new int(7);
  escape(one);
  delete one;
  auto* many = new int[16];
  escape(many);
  delete[] many;
  struct alignas(64) Wide {
    char c[64];
  };
  auto* wide = new Wide;
  escape(wide);
  delete wide;
  auto* maybe = new (std::nothrow) int;
  escape(maybe);
  delete maybe;
  EXPECT_EQ(counter.allocations(), 4U);
  EXPECT_GE(counter.bytes(), sizeof(int) + 16 * sizeof(int) + 64 + sizeof(int));
}

TEST(AllocCounter, CountsMallocFamily) {
  AllocationCounter counter;
  void* a = std::malloc(10);
  escape(a);
  void* b = std::calloc(4, 8);
  escape(b);
  a = std::realloc(a, 100);
  escape(a);
  void* c = std::aligned_alloc(64, 128);
  escape(c);
  std::free(a);
  std::free(b);
  std::free(c);
  EXPECT_EQ(counter.allocations(), 4U);
}

TEST(AllocCounter, CountsStandardContainersAndOtherThreads) {
  AllocationCounter counter;
  std::vector<int> v;
  v.reserve(100);
  escape(v.data());
  std::string s(200, 'x');  // beyond the small-string buffer
  escape(s.data());
  EXPECT_EQ(counter.allocations(), 2U);

  AllocationCounter threadCounter;
  std::thread worker([] {
    auto p = std::make_unique<double[]>(1000);
    escape(p.get());
  });
  worker.join();
  // The thread's own state counts too; at least the array must be seen.
  EXPECT_GE(threadCounter.allocations(), 1U);
  EXPECT_GE(threadCounter.bytes(), 8000U);
}

TEST(AllocCounter, ScopesNest) {
  AllocationCounter outer;
  auto first = std::make_unique<int>(1);
  escape(first.get());
  {
    AllocationCounter inner;
    auto second = std::make_unique<int>(2);
    escape(second.get());
    EXPECT_EQ(inner.allocations(), 1U);
  }
  EXPECT_EQ(outer.allocations(), 2U);
}

}  // namespace
}  // namespace smx::test
