// A small fork-join pool of threads for the stages of a step: the caller and
// threads() - 1 workers run one task together, and the call returns when all
// of them have finished it. The stages hand it work whose result does not
// depend on which thread does which part (each part writes only its own
// outputs), so a step's result is the same for any number of threads.
//
// A step hands the pool a dozen tasks, microseconds to a millisecond apart.
// Waking a blocked thread costs tens of microseconds on a virtual machine
// (a futex call, then the scheduler), as much as a small stage's work; so a
// worker spins for a new task for kWorkerSpin after each one, and the
// caller spins for the workers to finish, before either blocks. Between
// steps (a node stepping in real time waits most of its period) the
// workers block, so an idle world costs no core.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_TASK_POOL_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_TASK_POOL_H_

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

  // Runs task(t) once for each t in [0, threads()), t = 0 on the calling
  // thread, and returns when every call has returned. Not reentrant: a
  // task must not call RunOnAll.
  void RunOnAll(const std::function<void(int)>& task);

  // Calls body(i) for every i in [0, count): the threads take chunks of
  // `chunk` consecutive indices in turn until none are left, so uneven
  // parts balance. Which thread runs an index is left to the schedule;
  // body must write only what index i owns.
  template <typename Body>
  void ParallelFor(std::size_t count, std::size_t chunk, const Body& body) {
    if (threads() == 1 || count <= chunk) {
      for (std::size_t i = 0; i < count; ++i) body(i);
      return;
    }
    std::atomic<std::size_t> next{0};
    RunOnAll([&](int) {
      for (;;) {
        const std::size_t begin = next.fetch_add(chunk, std::memory_order_relaxed);
        if (begin >= count) return;
        const std::size_t end = begin + chunk < count ? begin + chunk : count;
        for (std::size_t i = begin; i < end; ++i) body(i);
      }
    });
  }

 private:
  void WorkerLoop(int index);
  // Blocks until a task newer than `seen`, or stop_; returns false on stop_.
  bool AwaitTask(std::uint64_t seen);
  // Returns when every worker has finished the current task.
  void AwaitWorkers();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;  // a new task, or stop_
  std::condition_variable done_;   // pending_ reached 0
  const std::function<void(int)>* task_ = nullptr;
  // generation_'s release store publishes task_ and pending_.
  std::atomic<std::uint64_t> generation_{0};  // counts the tasks handed out
  std::atomic<int> pending_{0};               // workers still running the current task
  // Threads that stopped spinning and block, or are about to: a waker
  // reads them after its own store (both sequentially consistent), so one
  // of the two sides always sees the other.
  std::atomic<int> sleeping_workers_{0};
  std::atomic<bool> caller_sleeping_{false};
  std::atomic<bool> stop_{false};
};

// The threads a `threads` setting asks for: itself, or for 0 every core the
// system reports (at least 1).
int ResolveThreadCount(int threads);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_TASK_POOL_H_
