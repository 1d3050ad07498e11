#include "physics/task_pool.h"

namespace rigid_body_sim::physics {

int ResolveThreadCount(int threads) {
  if (threads > 0) return threads;
  const unsigned cores = std::thread::hardware_concurrency();
  return cores > 0 ? static_cast<int>(cores) : 1;
}

TaskPool::TaskPool(int threads) {
  for (int index = 1; index < threads; ++index) workers_.emplace_back([this] { WorkerLoop(); });
}

TaskPool::~TaskPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void TaskPool::Share(const std::function<void()>& work) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &work;
    open_ = true;
    ++generation_;
  }
  start_.notify_all();
  work();
  // Every index is taken. Workers that wake from now on skip the job; the
  // ones running it finish their chunks.
  std::unique_lock<std::mutex> lock(mutex_);
  open_ = false;
  done_.wait(lock, [this] { return active_ == 0; });
  job_ = nullptr;
}

void TaskPool::WorkerLoop() {
  std::uint64_t seen = 0;
  for (;;) {
    const std::function<void()>* job = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (!open_) continue;
      job = job_;
      ++active_;
    }
    (*job)();
    bool last = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      last = --active_ == 0;
    }
    if (last) done_.notify_one();
  }
}

}  // namespace rigid_body_sim::physics
