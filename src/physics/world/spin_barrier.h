// A barrier for the threads of one TaskPool::RunOnAll task, between the
// stages of a task that must see each other's writes (the soft step's
// colours): each thread waits, spinning, until all have arrived. A wait
// costs well under a microsecond where the pool's own hand-over costs
// tens, which is what makes a hundred stages a step affordable. Threads
// that spin long yield, so a machine busier than its cores still makes
// progress.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_SPIN_BARRIER_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_SPIN_BARRIER_H_

#include <atomic>
#include <thread>

namespace rigid_body_sim::physics {

class SpinBarrier {
 public:
  explicit SpinBarrier(int threads) : threads_(threads) {}

  // Returns once every one of the threads has called Wait as often as this
  // one. The last to arrive opens the next phase: its release store, and the
  // others' acquire loads, make every write before the barrier visible
  // after it.
  void Wait() {
    if (threads_ <= 1) return;
    const unsigned phase = phase_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == threads_) {
      arrived_.store(0, std::memory_order_relaxed);
      phase_.store(phase + 1, std::memory_order_release);
      return;
    }
    constexpr int kSpinsBeforeYield = 256;
    int spins = 0;
    while (phase_.load(std::memory_order_acquire) == phase) {
      if (++spins > kSpinsBeforeYield) std::this_thread::yield();
    }
  }

 private:
  const int threads_;
  std::atomic<int> arrived_{0};
  std::atomic<unsigned> phase_{0};
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_SPIN_BARRIER_H_
