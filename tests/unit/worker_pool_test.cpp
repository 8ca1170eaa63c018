// The firmware's two ways of running work off the calling thread: the worker pool (cameras, and
// the parts of one camera's frame) and the background job (decoding while the next frame is
// taken). Both must really run at once, each job exactly once, and allocate nothing per batch.
#include "smx/device/worker_pool.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <thread>

#include "alloc_counter.hpp"
#include "smx/device/background_job.hpp"

namespace smx::device {
namespace {

using namespace std::chrono_literals;

// Spins until `flag` is set or a second has passed; false on timeout (rather than hanging).
bool waitFor(const std::atomic<bool>& flag) {
  const auto deadline = std::chrono::steady_clock::now() + 1s;
  while (!flag) {
    if (std::chrono::steady_clock::now() > deadline) {
      return false;
    }
    std::this_thread::yield();
  }
  return true;
}

TEST(WorkerPool, EveryIndexRunsOnceAndTheBatchAllocatesNothing) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.width(), 4);
  // Warm-up: four jobs that each wait for all four to start, so that every thread has run one
  // (a thread's first run may allocate, under the sanitisers for one; that is start-up).
  std::array<std::atomic<bool>, 4> started{};
  auto everyThread = [&](int i) {
    started[static_cast<std::size_t>(i)] = true;
    for (const auto& other : started) {
      ASSERT_TRUE(waitFor(other));
    }
  };
  pool.forEach(4, everyThread);
  std::array<std::atomic<int>, 37> runs{};
  auto job = [&](int i) { ++runs[static_cast<std::size_t>(i)]; };
  const test::AllocationCounter allocations;
  for (int batch = 0; batch < 50; ++batch) {
    pool.forEach(37, job);
  }
  EXPECT_EQ(allocations.allocations(), 0U);
  for (const auto& r : runs) {
    EXPECT_EQ(r, 50);
  }
}

TEST(WorkerPool, TwoJobsRunAtOnce) {
  WorkerPool pool(1);
  std::array<std::atomic<bool>, 2> started{};
  std::array<bool, 2> sawTheOther{};
  // Each job waits for the other to start: only true concurrency lets both see it.
  auto job = [&](int i) {
    const auto me = static_cast<std::size_t>(i);
    started[me] = true;
    sawTheOther[me] = waitFor(started[1 - me]);
  };
  pool.forEach(2, job);
  EXPECT_TRUE(sawTheOther[0]);
  EXPECT_TRUE(sawTheOther[1]);
}

TEST(BackgroundJob, StartReturnsAtOnceAndWaitReturnsWhenTheJobIsDone) {
  BackgroundJob background;
  std::atomic<bool> release = false;
  std::atomic<bool> done = false;
  struct Context {
    std::atomic<bool>* release;
    std::atomic<bool>* done;
  } context{&release, &done};
  const auto call = [](void* c) {
    auto* flags = static_cast<Context*>(c);
    (void)waitFor(*flags->release);
    *flags->done = true;
  };
  for (int round = 0; round < 3; ++round) {
    release = false;
    done = false;
    background.start(&context, call);
    // The job cannot end before this thread releases it: start() did not run it here.
    EXPECT_FALSE(done);
    release = true;
    background.wait();
    EXPECT_TRUE(done);
  }
  background.wait();  // with nothing started, at once
}

}  // namespace
}  // namespace smx::device
