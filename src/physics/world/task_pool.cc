#include "physics/world/task_pool.h"

#include <chrono>

namespace rigid_body_sim::physics {

int ResolveThreadCount(int threads) {
  if (threads > 0) return threads;
  const unsigned cores = std::thread::hardware_concurrency();
  return cores > 0 ? static_cast<int>(cores) : 1;
}

namespace {

// How long a worker spins for its next task, and the caller for the
// workers, before blocking: longer than the gaps between a step's tasks
// (the serial stages between them take up to a few hundred microseconds in
// the big scenes), short next to a real-time node's step period.
constexpr std::chrono::microseconds kWorkerSpin{250};
constexpr std::chrono::microseconds kCallerSpin{2000};

void Relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Spins until ready() or `budget` has passed; returns ready(). After the
// first spins it yields, so that on a machine with fewer free cores than
// threads the thread it waits for can run.
template <typename Ready>
bool SpinUntil(const Ready& ready, std::chrono::microseconds budget) {
  constexpr int kSpinsBeforeYield = 512;
  constexpr int kSpinsPerClockRead = 64;
  const auto deadline = std::chrono::steady_clock::now() + budget;
  for (int spins = 1;; ++spins) {
    if (ready()) return true;
    if (spins < kSpinsBeforeYield) {
      Relax();
    } else {
      std::this_thread::yield();
    }
    if (spins % kSpinsPerClockRead == 0 && std::chrono::steady_clock::now() > deadline) {
      return ready();
    }
  }
}

}  // namespace

TaskPool::TaskPool(int threads) {
  for (int index = 1; index < threads; ++index) {
    workers_.emplace_back([this, index] { WorkerLoop(index); });
  }
}

TaskPool::~TaskPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_.store(true);
  }
  start_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void TaskPool::RunOnAll(const std::function<void(int)>& task) {
  if (workers_.empty()) {
    task(0);
    return;
  }
  task_ = &task;
  pending_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
  generation_.fetch_add(1);
  if (sleeping_workers_.load() > 0) {
    // Taking the lock orders this notify after a sleeper's last check.
    { std::lock_guard<std::mutex> lock(mutex_); }
    start_.notify_all();
  }
  task(0);
  AwaitWorkers();
  task_ = nullptr;
}

void TaskPool::AwaitWorkers() {
  auto finished = [this] { return pending_.load(std::memory_order_acquire) == 0; };
  if (SpinUntil(finished, kCallerSpin)) return;
  std::unique_lock<std::mutex> lock(mutex_);
  caller_sleeping_.store(true);
  done_.wait(lock, [this] { return pending_.load() == 0; });
  caller_sleeping_.store(false);
}

bool TaskPool::AwaitTask(std::uint64_t seen) {
  auto ready = [&] {
    return stop_.load(std::memory_order_relaxed) ||
           generation_.load(std::memory_order_acquire) != seen;
  };
  if (!SpinUntil(ready, kWorkerSpin)) {
    std::unique_lock<std::mutex> lock(mutex_);
    sleeping_workers_.fetch_add(1);
    start_.wait(lock, [&] { return stop_.load() || generation_.load() != seen; });
    sleeping_workers_.fetch_sub(1);
  }
  return !stop_.load();
}

void TaskPool::WorkerLoop(int index) {
  std::uint64_t seen = 0;
  while (AwaitTask(seen)) {
    seen = generation_.load(std::memory_order_acquire);
    (*task_)(index);
    if (pending_.fetch_sub(1) == 1 && caller_sleeping_.load()) {
      { std::lock_guard<std::mutex> lock(mutex_); }
      done_.notify_one();
    }
  }
}

}  // namespace rigid_body_sim::physics
