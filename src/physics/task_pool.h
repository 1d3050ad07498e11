// A small fork-join pool of threads for the stages of a step. ParallelFor
// shares the indices of one loop among the caller and threads() - 1
// workers, in chunks that each thread takes while any are left, and returns
// when every index is done. The stages hand it work whose result does not
// depend on which thread does which part (each index writes only what it
// owns), so a step's result is the same for any number of threads.
//
// The caller never waits for a worker that has not started: it takes
// chunks itself, and once none are left it waits only for the workers that
// are still running one. On a machine with no core to spare, a worker that
// the scheduler has not run yet costs the step nothing; the step then takes
// as long as on one thread.
#ifndef RIGID_BODY_SIM_PHYSICS_TASK_POOL_H_
#define RIGID_BODY_SIM_PHYSICS_TASK_POOL_H_

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace rigid_body_sim::physics {

class TaskPool {
 public:
  // `threads` >= 1 threads in all, the caller's included; 1 starts none.
  explicit TaskPool(int threads = 1);
  ~TaskPool();
  TaskPool(const TaskPool&) = delete;
  TaskPool& operator=(const TaskPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(i) for every i in [0, count): the threads take chunks of
  // `chunk` consecutive indices in turn until none are left, so uneven
  // parts balance. Which thread runs an index is left to the schedule;
  // body must write only what index i owns. Not reentrant: body must not
  // call ParallelFor.
  template <typename Body>
  void ParallelFor(std::size_t count, std::size_t chunk, const Body& body) {
    if (workers_.empty() || count <= chunk) {
      for (std::size_t i = 0; i < count; ++i) body(i);
      return;
    }
    std::atomic<std::size_t> next{0};
    Share([&] {
      for (;;) {
        const std::size_t begin = next.fetch_add(chunk, std::memory_order_relaxed);
        if (begin >= count) return;
        const std::size_t end = begin + chunk < count ? begin + chunk : count;
        for (std::size_t i = begin; i < end; ++i) body(i);
      }
    });
  }

 private:
  // Runs `work` on the caller and on every worker that wakes while it is
  // open; `work` returns once nothing is left to take. Returns when the
  // caller's call and every worker's call that started have returned.
  void Share(const std::function<void()>& work);
  void WorkerLoop();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;  // a new job, or stop_
  std::condition_variable done_;   // active_ reached 0
  const std::function<void()>* job_ = nullptr;
  std::uint64_t generation_ = 0;  // counts the jobs handed out
  bool open_ = false;             // workers that wake may still join job_
  int active_ = 0;                // workers running job_
  bool stop_ = false;
};

// The threads a `threads` setting asks for: itself, or for 0 every core the
// system reports (at least 1).
int ResolveThreadCount(int threads);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_TASK_POOL_H_
