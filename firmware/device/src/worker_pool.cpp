#include "smx/device/worker_pool.hpp"

namespace smx::device {

WorkerPool::WorkerPool(int workers) {
  for (int i = 0; i < workers; ++i) {
    workers_.emplace_back([this] { workerLoop(); });
  }
}

WorkerPool::~WorkerPool() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
}

bool WorkerPool::runNext(std::unique_lock<std::mutex>& lock) {
  if (next_ >= count_) {
    return false;
  }
  const int index = next_++;
  ++running_;
  lock.unlock();
  call_(context_, index);
  lock.lock();
  if (--running_ == 0 && next_ >= count_) {
    done_.notify_all();
  }
  return true;
}

void WorkerPool::runJobs(int count, void* context, Call call) {
  std::unique_lock lock(mutex_);
  context_ = context;
  call_ = call;
  count_ = count;
  next_ = 0;
  ++batch_;
  wake_.notify_all();
  while (runNext(lock)) {
  }
  done_.wait(lock, [this] { return next_ >= count_ && running_ == 0; });
}

void WorkerPool::workerLoop() {
  std::unique_lock lock(mutex_);
  std::uint64_t seen = 0;
  while (true) {
    wake_.wait(lock, [&] { return stopping_ || batch_ != seen; });
    if (stopping_) {
      return;
    }
    seen = batch_;
    while (runNext(lock)) {
    }
  }
}

}  // namespace smx::device
