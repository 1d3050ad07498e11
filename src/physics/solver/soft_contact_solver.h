// The soft step (docs/design.md, "The soft step"): the contact solve and
// the integration of one step in n sub-steps of h = dt / n, after Catto,
// "Solver2D" (2024) and Box2D v3's solver. Each sub-step
//   1. integrates the velocities:   v += h (g + F/m), w += h I^-1 tau;
//   2. warm-starts every contact with its impulse of the last sub-step;
//   3. solves every contact once, softly: with s the point's separation now
//      and v_n its normal velocity,
//        s > 0 (speculative):  v_n >= -s / h, a rigid row;
//        s <= 0:  dl = -m_n S_m (v_n + max(b s, -v_push)) - S_i l,
//      the implicit mass-spring-damper of natural frequency f and damping
//      ratio z (w = 2 pi f, a1 = 2 z + h w, a2 = h w a1, b = w / a1,
//      S_m = a2 / (1 + a2), S_i = 1 / (1 + a2)); the accumulated impulse
//      l >= 0; then friction, |l_t| <= mu l;
//   4. integrates the positions:    x += h v, q += h/2 (0, w) q;
//   5. relaxes: step 3 again with the spring's bias removed (a rigid row
//      v_n >= 0), so that the push that separated the bodies leaves no
//      velocity behind.
// After the sub-steps a restitution pass gives each point that closed
// faster than the collision threshold v_n >= -e v_approach. Contacts are
// solved colour by colour (constraint_colouring.h): the contacts of one
// colour share no moving body, so each colour is shared among the threads
// and the result is the same for any number of threads.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_SOLVER_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_SOLVER_H_

#include <array>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/solver/constraint_colouring.h"
#include "physics/solver/contact_solver.h"
#include "physics/solver/soft_contact_lanes.h"
#include "physics/solver/soft_contact_rows.h"
#include "physics/world/spin_barrier.h"
#include "physics/world/task_pool.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// A body as the soft step loads it: velocities at the step's start, what
// the sub-steps hold constant, and its motion when the step is done.
struct SoftBody {
  Vec3 linear_velocity = Vec3::Zero();       // m/s (in, out)
  Vec3 angular_velocity = Vec3::Zero();      // rad/s, world (in, out)
  Vec3 position = Vec3::Zero();              // m, centre of mass at the step's start
  Quat orientation = Quat::Identity();       // world_from_principal at the step's start
  Vec3 delta_position = Vec3::Zero();        // m, moved over the step (out)
  Quat delta_rotation = Quat::Identity();    // turned over the step, world (out)
  Vec3 linear_acceleration = Vec3::Zero();   // m/s^2: g + F / m
  Vec3 angular_acceleration = Vec3::Zero();  // rad/s^2: I^-1 tau
  double inverse_mass = 0.0;                 // 1/kg; 0: the solve never moves it
  Mat3 inverse_inertia_world = Mat3::Zero();
  double reach = 0.0;   // m, largest distance of a shape point from the centre
  double travel = 0.0;  // m, a bound on how far any of its points moved (out)
  bool moving = false;  // written by the solve
};

// What the sub-steps read of the world.
struct SoftStepInput {
  double dt = 0.0;  // s, the whole step
  SoftStepSettings settings;
  double collision_velocity_threshold = 0.0;  // m/s
  double touch_tolerance = 0.0;               // m: a point this close touches
  // The bodies the step may move (those of them whose SoftBody::moving is
  // set); with the manifolds' bodies, the only ones it reads, so bodies
  // asleep and out of contact cost nothing.
  const std::vector<std::uint32_t>* moving = nullptr;
  // Each manifold's (body_a, body_b), in the manifolds' order.
  const std::vector<std::array<std::uint32_t, 2>>* manifold_bodies = nullptr;
  // The manifolds' colours (ColourConstraints on their bodies, with the
  // moving bodies those whose SoftBody::moving is set), the manifolds in
  // its order: colour c is manifolds [colour_start[c], colour_start[c + 1]),
  // the overflow set last.
  const ConstraintColouring* colouring = nullptr;
};

class SoftContactSolver {
 public:
  // Runs the step on `bodies` (indexed by the manifolds' body_a and
  // body_b), whose moving ones end at their new velocities and with their
  // motion in delta_position and delta_rotation (and travel). Each manifold's points
  // start from their normal_impulse and tangent_impulse (the step's, as the
  // contact cache keeps them) and end with the step's impulses, their type
  // (colliding when they closed faster than the threshold) and the normal
  // velocity they closed at.
  // `anchors` holds one per manifold, as last step left it; on return, as
  // this step leaves it.
  void Step(const SoftStepInput& input, TaskPool* pool, std::vector<SoftBody>* bodies,
            std::vector<SolverManifold>* manifolds, std::vector<FrictionAnchor>* anchors);

 private:
  using State = SoftRowState;
  using Point = SoftPoint;
  using Constraint = SoftConstraint;
  enum class Pass { kWarmStart, kSolve, kRelax, kRestitution };
  struct PairVelocities;  // soft_contact_solver.cc

  // The rows' preparing (soft_contact_prepare.cc): a constraint's frame,
  // as its rows keep it; one constraint for the scalar update; a block's
  // constraints first to first + lanes - 1 straight into its lanes.
  struct Frame;
  void MakeSoftnesses(const SoftStepInput& input);
  Frame MakeFrame(const SoftBody& a, const SoftBody& b, const SolverManifold& manifold,
                  const FrictionAnchor& anchor) const;
  void Prepare(const std::vector<SoftBody>& bodies, const SolverManifold& manifold,
               const FrictionAnchor& anchor, Constraint* constraint);
  void PrepareFriction(const SoftBody& a, const SoftBody& b, const Frame& frame,
                       Constraint* constraint) const;
  template <typename Block>
  void PrepareBlock(std::uint32_t first, int lanes, Block* block);
  // Stage `pass` on the constraints, colour after colour, the overflow
  // last; thread `thread` of `threads` takes its share of each colour.
  void RunPass(Pass pass, int thread, int threads, SpinBarrier* barrier);
  void Apply(Pass pass, Constraint* constraint);
  void WarmStart(Constraint* constraint);
  void Solve(Constraint* constraint, bool use_bias);
  void SolveFriction(Constraint* constraint, bool use_bias, PairVelocities* velocities) const;
  void Restitute(Constraint* constraint);
  void IntegrateVelocities(int thread, int threads);
  void IntegratePositions(int thread, int threads);
  void RunSubsteps(int thread, int threads, SpinBarrier* barrier);
  // The blocks of four constraints of one colour for the lane updates
  // (soft_contact_lanes.h); this thread's share of their preparing, and of
  // their restitution and store after the sub-steps.
  void LoadStates(const SoftStepInput& input);
  void ListBlocks();
  void PrepareBlocks(int thread, int threads);
  void PrefetchBodies(std::uint32_t first, std::uint32_t end) const;
  // Blocks ahead of the one being prepared whose bodies start loading
  // (pyramid_90 on one thread: 0.95 of the awake step without;
  // docs/performance.md).
  static constexpr std::uint32_t kBodiesAhead = 2;
  void StoreBlocks(bool bounce, int thread, int threads, SpinBarrier* barrier);
  // The lane updates of `pass` on this thread's share of colour `colour`'s
  // blocks.
  void ApplyToBlocks(Pass pass, int colour, int thread, int threads);
  // This thread's share [begin, end) of colour `colour`'s blocks.
  std::pair<std::size_t, std::size_t> ColourBlocks(int colour, int thread, int threads) const;
  // Whether this step's constraints are in blocks (simd_lanes, and some).
  bool HasBlocks() const { return lanes_ && block_start_.back() > 0; }
  // f(blocks) with this step's layout's vector of blocks.
  template <typename F>
  void WithBlocks(const F& f) {
    if (compact_) {
      f(compact_blocks_);
    } else {
      f(blocks_);
    }
  }
  void StoreAnchor(const Constraint& constraint, FrictionAnchor* anchor) const;
  // Constraint k's results into its manifold and its friction anchor.
  void Store(std::size_t k, const Constraint& constraint) const;

  std::vector<SoftBody>* bodies_ = nullptr;
  std::vector<SolverManifold>* manifolds_ = nullptr;
  std::vector<FrictionAnchor>* anchors_ = nullptr;
  std::vector<State> states_;          // per body of bodies_
  std::vector<std::uint32_t> moving_;  // indices of the moving bodies
  // Constraint k is manifold k's; with lanes only the overflow set's are
  // written, the blocks holding the others.
  std::vector<Constraint> constraints_;
  const ConstraintColouring* colouring_ = nullptr;  // SoftStepInput::colouring
  std::vector<std::uint8_t> moving_mask_;           // per body
  bool lanes_ = true;                               // SoftStepSettings::simd_lanes
  int compact_blocks_from_ = 0;                     // SoftStepSettings::compact_blocks_from
  // The blocks, this step's first block_start_.back() of blocks_ or
  // (compact_) of compact_blocks_; each vector only grows, so a layout met
  // again is not allocated again.
  bool compact_ = false;
  std::vector<SoftLaneBlock> blocks_;
  std::vector<CompactSoftLaneBlock> compact_blocks_;
  std::vector<std::uint32_t> block_start_;  // colour c's blocks: [block_start_[c], [c + 1])
  double h_ = 0.0;                          // s, the sub-step
  int substeps_ = 1;
  double max_push_velocity_ = 0.0;
  double collision_velocity_threshold_ = 0.0;
  double touch_tolerance_ = 0.0;
  double load_tracking_ = 0.0;
  // The spring's bias rate (1/s), mass scale and impulse scale, as the rows
  // keep them: [1] between two moving bodies, [0] with one that does not
  // move (MakeSoftnesses).
  struct KeptSoftness {
    double bias_rate;
    double mass_scale;
    double impulse_scale;
  };
  std::array<KeptSoftness, 2> softness_{};
  // Some point closed faster than the collision threshold this step (or
  // carried such a closing over): the restitution pass has work. Written by
  // any thread, only ever to true, and read after a barrier.
  std::atomic<bool> may_bounce_{false};
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_SOLVER_H_
