// A free articulation's step allocates nothing once its buffers have their
// size (buffers sized at spawn, not per step). Allocations are counted at
// malloc, where operator new and Eigen's dynamic matrices both end: malloc
// is replaced in this test binary (glibc's __libc_malloc does the work), or,
// under AddressSanitizer or ThreadSanitizer, which replace it themselves,
// counted by their allocation hook.
#include <atomic>
#include <cstddef>

#include <gtest/gtest.h>

#include "articulation_fixtures.h"
#include "scene.h"

namespace {
std::atomic<long> allocations{0};
}  // namespace

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
// The sanitizer runtime's hook API (sanitizer/allocator_interface.h, which
// GCC's packages do not install).
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*,
                                                                             std::size_t),
                                                         void (*free_hook)(const volatile void*));

namespace {
void CountAllocation(const volatile void* /*pointer*/, std::size_t /*size*/) {
  allocations.fetch_add(1, std::memory_order_relaxed);
}
void IgnoreFree(const volatile void* /*pointer*/) {}
const int kHooksInstalled = __sanitizer_install_malloc_and_free_hooks(CountAllocation, IgnoreFree);
}  // namespace
#else
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);

void* malloc(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  *out = __libc_memalign(alignment, size);
  return *out == nullptr ? 12 : 0;  // ENOMEM
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
}
#endif

namespace rigid_body_sim::physics::testing {
namespace {

// Allocations of the next `steps` steps.
long AllocationsOfSteps(World* world, int steps) {
  const long before = allocations.load();
  for (int i = 0; i < steps; ++i) world->Step();
  return allocations.load() - before;
}

// A limp seven-joint chain swinging from 0.4 rad per joint, nothing to
// touch: every step is the free RK4 step (split where the energy balance
// asks), and none allocates once the first has sized the buffers.
TEST(ArticulationAllocationTest, FreeSwingingChainStepsWithoutAllocating) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links.push_back(Anchor());
  for (int i = 1; i <= 7; ++i) {
    def.links.push_back(Rod(1.0 + 0.5 * i, 0.2));
    def.joints.push_back(Hinge(i, i == 1 ? 0.0 : 0.2, 0.4));
  }
  ASSERT_TRUE(world.CreateArticulation(def).ok());
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  ASSERT_NE(kHooksInstalled, 0) << "the sanitizer's allocation hooks were all taken";
#endif
  // The first step sizes the buffers: the count sees it, so it counts.
  EXPECT_GT(AllocationsOfSteps(&world, 1), 0);
  AllocationsOfSteps(&world, 9);
  EXPECT_EQ(AllocationsOfSteps(&world, 480), 0);
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
