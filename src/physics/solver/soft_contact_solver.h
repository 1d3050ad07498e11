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
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/solver/constraint_colouring.h"
#include "physics/solver/contact_solver.h"
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

  const ConstraintColouring& colouring() const { return colouring_; }

 private:
  // What the rows read and write of a body in the sub-steps, packed: the
  // velocities, and the motion since the step began, dx and the rotation
  // vector dtheta = sum h w, which the rows use to first order (a point r
  // from the centre has moved dx + dtheta x r).
  struct State {
    Vec3 linear_velocity;
    Vec3 angular_velocity;
    Vec3 delta_position;
    Vec3 delta_angle;
    Quat delta_rotation;  // the same turn, exactly, for the new pose
  };
  // A normal row, with its Jacobian's angular parts r x n and I^-1 (r x n)
  // precomputed: v_n = n.(v_a - v_b) + (r_a x n).w_a - (r_b x n).w_b.
  struct Point {
    Vec3 rn_a;  // r_a x n
    Vec3 rn_b;
    Vec3 ang_a;  // I_a^-1 (r_a x n)
    Vec3 ang_b;
    double start_separation;    // m, s0
    double normal_mass;         // kg
    double normal_impulse;      // N s, of the current sub-step
    double preload;             // N s per sub-step (CachedImpulse::preload)
    double max_normal_impulse;  // N s, the largest push of any sub-step
    double total_normal_impulse;
    double approach_velocity;  // m/s, v_n as the point closed (< 0: approaching)
    bool closed;               // a sub-step's motion would close its gap
    bool carried;              // closed in the last step (its approach_velocity is that)
    bool touched;              // closed, and within touch_tolerance at the step's end
  };
  // A manifold's rows. Friction acts at the points' centroid c: two tangent
  // rows (their 2x2 block inverted) and a twist row about the normal, bounded
  // by mu times the manifold's whole normal impulse (times the points' mean
  // distance from c, for the twist).
  struct Constraint {
    std::uint32_t body_a;
    std::uint32_t body_b;
    Vec3 normal;  // from B to A
    std::array<Vec3, 2> tangent;
    double inverse_mass_a;
    double inverse_mass_b;
    double friction;
    double restitution;
    double bias_rate;  // 1/s
    double mass_scale;
    double impulse_scale;
    int point_count;
    std::array<Vec3, 2> ct_a;  // c_a x t_k
    std::array<Vec3, 2> ct_b;
    std::array<Vec3, 2> ang_t_a;  // I_a^-1 (c_a x t_k)
    std::array<Vec3, 2> ang_t_b;
    Vec3 twist_a;  // I_a^-1 n
    Vec3 twist_b;
    std::array<double, 3> tangent_block;  // K_t^-1: xx, xy, yy, kg
    double twist_mass;                    // kg m^2
    double twist_arm;                     // m
    // The friction anchors (FrictionAnchor) as offsets from the centres of
    // mass at the step's start; their slip along t_k at the start, and
    // anchor x t_k for its change with the bodies' turn.
    Vec3 anchor_a;
    Vec3 anchor_b;
    std::array<double, 2> slip_start;
    std::array<Vec3, 2> anchor_t_a;
    std::array<Vec3, 2> anchor_t_b;
    std::array<double, 2> tangent_impulse;  // N s, of the current sub-step
    double twist_impulse;                   // N m s
    std::array<double, 2> total_tangent_impulse;
    std::array<Point, ContactManifold::kMaxPoints> points;
  };
  enum class Pass { kWarmStart, kSolve, kRelax, kRestitution };
  struct PairVelocities;  // soft_contact_solver.cc

  void Prepare(const SoftStepInput& input, const std::vector<SoftBody>& bodies,
               const SolverManifold& manifold, const FrictionAnchor& anchor,
               Constraint* constraint);
  void PrepareFriction(const SoftBody& a, const SoftBody& b, const SolverManifold& manifold,
                       const FrictionAnchor& anchor, double share, Constraint* constraint) const;
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
  void StoreAnchor(const Constraint& constraint, FrictionAnchor* anchor) const;
  void Store(const Constraint& constraint, SolverManifold* manifold, FrictionAnchor* anchor) const;

  std::vector<SoftBody>* bodies_ = nullptr;
  std::vector<State> states_;          // per body of bodies_
  std::vector<std::uint32_t> moving_;  // indices of the moving bodies
  std::vector<Constraint> constraints_;
  ConstraintColouring colouring_;
  std::vector<std::uint32_t> body_a_;  // per constraint, for the colouring
  std::vector<std::uint32_t> body_b_;
  std::vector<std::uint8_t> moving_mask_;  // per body
  std::vector<std::uint32_t> colour_masks_;
  std::vector<std::uint8_t> colour_of_;
  double h_ = 0.0;  // s, the sub-step
  int substeps_ = 1;
  double max_push_velocity_ = 0.0;
  double collision_velocity_threshold_ = 0.0;
  double touch_tolerance_ = 0.0;
  double load_tracking_ = 0.0;
  // Some point closed faster than the collision threshold this step (or
  // carried such a closing over): the restitution pass has work. Written by
  // any thread, only ever to true, and read after a barrier.
  std::atomic<bool> may_bounce_{false};
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_SOLVER_H_
