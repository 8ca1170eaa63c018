#pragma once

// The independent parts of one frame's work, and who runs them: the camera pipeline hands each
// projector's decoding and triangulation, and bands of rows of its merge, to a JobRunner. The
// firmware's worker pool runs them on several cores; SerialJobs runs them in order on the caller.
// Dispatch is a plain function pointer and context: a frame's work allocates nothing.
namespace smx::algo {

class JobRunner {
 public:
  using Call = void (*)(void* context, int index);

  // Runs call(context, i) for every i in [0, count), each once, and returns when all are done.
  virtual void runJobs(int count, void* context, Call call) = 0;
  // How many jobs can run at once (≥ 1): the number of bands worth cutting a stage into.
  [[nodiscard]] virtual int width() const = 0;

  template <class Job>
  void forEach(int count, Job& job) {
    runJobs(count, &job, [](void* context, int index) { (*static_cast<Job*>(context))(index); });
  }

 protected:
  JobRunner() = default;
  ~JobRunner() = default;
  JobRunner(const JobRunner&) = default;
  JobRunner& operator=(const JobRunner&) = default;
};

class SerialJobs final : public JobRunner {
 public:
  void runJobs(int count, void* context, Call call) override {
    for (int i = 0; i < count; ++i) {
      call(context, i);
    }
  }
  [[nodiscard]] int width() const override { return 1; }
};

}  // namespace smx::algo
