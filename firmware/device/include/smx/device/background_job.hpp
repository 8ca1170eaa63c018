#pragma once

#include <condition_variable>
#include <mutex>
#include <thread>

// One thread that runs a job handed to it while the caller goes on: the capture loop takes the
// next frame while the previous one decodes. start() and wait() take turns; the job is a plain
// function pointer and context, so handing it over allocates nothing.
namespace smx::device {

class BackgroundJob {
 public:
  BackgroundJob();
  ~BackgroundJob();
  BackgroundJob(const BackgroundJob&) = delete;
  BackgroundJob& operator=(const BackgroundJob&) = delete;
  BackgroundJob(BackgroundJob&&) = delete;
  BackgroundJob& operator=(BackgroundJob&&) = delete;

  using Call = void (*)(void* context);
  // Runs call(context) on the thread; what `context` points to must live until wait() returns.
  // One job at a time: the caller waits for the last before starting the next.
  void start(void* context, Call call);
  // Returns once the started job is done (at once when none is).
  void wait();

 private:
  void loop(const std::stop_token& stop);

  std::mutex mutex_;
  std::condition_variable_any changed_;
  void* context_ = nullptr;
  Call call_ = nullptr;  // set while a job waits or runs
  std::jthread thread_;  // last: it starts after the members it uses exist
};

}  // namespace smx::device
