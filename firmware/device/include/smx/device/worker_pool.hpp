#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "smx/algo/jobs.hpp"

// Runs job(i) for i in [0, count) on the calling thread and a fixed set of workers started at
// construction: the capture loop decodes its cameras in parallel, and each camera's pipeline
// hands the parts of one frame to a pool of its own. Dispatch takes a plain function pointer and
// context, so a frame's work allocates nothing.
namespace smx::device {

class WorkerPool final : public algo::JobRunner {
 public:
  explicit WorkerPool(int workers);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  WorkerPool(WorkerPool&&) = delete;
  WorkerPool& operator=(WorkerPool&&) = delete;

  void runJobs(int count, void* context, Call call) override;
  [[nodiscard]] int width() const override { return static_cast<int>(workers_.size()) + 1; }

 private:
  void workerLoop();
  // Takes the next index of the current batch; false when none is left.
  bool runNext(std::unique_lock<std::mutex>& lock);

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  std::vector<std::jthread> workers_;
  void* context_ = nullptr;
  Call call_ = nullptr;
  int count_ = 0;
  int next_ = 0;
  int running_ = 0;
  std::uint64_t batch_ = 0;
  bool stopping_ = false;
};

}  // namespace smx::device
