#include "smx/device/background_job.hpp"

namespace smx::device {

BackgroundJob::BackgroundJob() : thread_([this](const std::stop_token& stop) { loop(stop); }) {}

// The thread is stopped and joined by its jthread, the last member, first destroyed.
BackgroundJob::~BackgroundJob() {
  wait();
}

void BackgroundJob::start(void* context, Call call) {
  {
    const std::lock_guard lock(mutex_);
    context_ = context;
    call_ = call;
  }
  changed_.notify_all();
}

void BackgroundJob::wait() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return call_ == nullptr; });
}

void BackgroundJob::loop(const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  while (changed_.wait(lock, stop, [this] { return call_ != nullptr; })) {
    const Call call = call_;
    void* const context = context_;
    lock.unlock();
    call(context);
    lock.lock();
    call_ = nullptr;
    changed_.notify_all();
  }
}

}  // namespace smx::device
