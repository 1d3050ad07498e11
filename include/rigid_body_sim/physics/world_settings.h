// Settings of a World, with their units and ranges, and the per-stage
// timing of its last step.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_SETTINGS_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_SETTINGS_H_

#include <cstddef>
#include <cstdint>

#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct SolverSettings {
  // PGS sweeps over the resting-contact rows per step, at most.
  int velocity_iterations = 20;
  // m/s; an island's sweeps stop early once none of its contact points'
  // relative velocities changes by more than this from one sweep to the next
  // (0: always velocity_iterations).
  double velocity_tolerance = 1e-6;
  // Sweeps of the split-impulse position correction per step.
  int position_iterations = 6;
  // Whether a sweep updates two runs of rows that share no moving body side
  // by side (ScheduleRuns), which gives bit for bit the result of updating
  // one run at a time in manifold order (false, the reference) in less time.
  bool interleave_independent_runs = true;
  // Whether a sweep updates up to four runs of rows that share no moving
  // body at once, one per lane of a SIMD vector (resting_batches.h), which
  // gives bit for bit the result of the order above in less time; false
  // sweeps in that order, the reference.
  bool batch_independent_runs = true;
  // m/s; epsilon of the classification: colliding when v_r < -epsilon,
  // resting when |v_r| <= epsilon.
  double collision_velocity_threshold = 0.01;
  // m; points closer than this are touching (the collision
  // tolerance epsilon of Baraff 1997, "Rigid Body Simulation II", section 6): only they collide or
  // rest. Closer points are reached by the time-of-impact search, so the approach speed, and the
  // bounce, is exact.
  double contact_tolerance = 1e-5;
  // m; penetration left alone, so resting contacts persist from step to step.
  double penetration_slop = 1e-4;
  // 1/step, in (0, 1]; fraction of the penetration beyond the slop removed per
  // step by the split impulse. It moves positions only and adds no energy.
  double position_correction = 0.2;
  // Rounds of simultaneous collision impulses before the remaining colliding
  // contacts are made perfectly inelastic.
  int max_collision_rounds = 32;
  // PGS sweeps within one collision round.
  int collision_iterations = 30;
  // Collision rounds with at most this many points solve the compression
  // exactly by pivoting; larger ones by PGS. A resting island with at most
  // this many points that the sweeps leave unconverged (a light body under a
  // heavy one) has its normal impulses solved by pivoting too, and is then
  // swept again.
  int max_pivoting_points = 32;
};

Status ValidateSolverSettings(const SolverSettings& settings);

// A body is slow when its speeds are below the thresholds, or when it has
// gone nowhere for time_to_sleep: its centre of mass and two points
// linear_velocity / angular_velocity from it have each stayed within a
// sphere of radius linear_velocity * time_to_sleep / 2 (rocking in place).
struct SleepSettings {
  bool enabled = true;
  double linear_velocity = 0.05;  // m/s; slower bodies may sleep
  double angular_velocity = 0.1;  // rad/s
  double time_to_sleep = 0.5;     // s an island must stay slow before it sleeps
  // s; a body whose speed or angular speed has grown at every step for this
  // long is getting under way, not settling, and keeps its island awake
  // however slow it still is: a box on a slope just steeper than its
  // friction angle, a ball on a gentle slope, a box tipping off an edge.
  // Speeds below 2 % of the thresholds above do not count. Long enough that
  // the slow sway of a large stack settling is not taken for it (in the
  // benchmark's 4,095-box pyramid a box's speed rises for up to 0.11 s).
  // 0 disables it.
  double speeding_up_time = 0.2;
};

// The most threads WorldSettings::threads may ask for.
constexpr int kMaxThreads = 256;

// The solver of the stages from velocities to positions (docs/design.md,
// "One step" and "The soft step"). kExact: Baraff's classification of every
// contact, exact collision impulses with restitution, resting contact for
// all contacts at once, and the time of impact found; the default.
// kSoftStep: sub-steps with one relaxed iteration of soft contacts each,
// colour by colour on every thread (Catto 2024, "Solver2D"), for big scenes
// that want speed first.
enum class MotionSolverKind : std::uint8_t { kExact, kSoftStep };

// The soft step's settings (MotionSolverKind::kSoftStep).
struct SoftStepSettings {
  // Sub-steps per step, in [1, kMaxSoftSubsteps]: each integrates the
  // velocities, solves every contact once with its softness, integrates the
  // positions and relaxes once.
  int substeps = 4;
  // Hz, > 0 and finite: the natural frequency of a contact's spring for its
  // effective mass (twice this against a body that does not move), at most
  // a quarter of the sub-step rate (a stiffer spring is not resolved by one
  // iteration a sub-step; Box2D v3 caps it the same way).
  double contact_hertz = 30.0;
  // The contact spring's damping ratio, finite and >= 0 (1: critical).
  double contact_damping_ratio = 10.0;
  // In [0, 1]: the fraction by which a contact's preload (the load its
  // spring carries at zero penetration) moves toward the load it carried,
  // each step. A plain soft contact (0) sags g / (2 pi f)^2 per weight it
  // carries: 0.28 mm per box at 30 Hz, centimetres under a tall stack. The
  // preload removes that sag at rest; larger values remove it sooner, but
  // beyond about 0.1 the tall stacks of the benchmark rock.
  double load_tracking = 0.05;
  // m/s, > 0: the fastest a contact's spring pushes penetrating bodies
  // apart (it moves them; it adds no momentum that stays).
  double max_push_velocity = 3.0;
  // Whether the sub-steps update four contacts of a colour at once, one per
  // lane of a SIMD vector (solver/soft_contact_lanes.h), which gives bit for
  // bit the result of one at a time in less time; false updates them one
  // at a time, the reference.
  bool simd_lanes = true;
  // Blocks, >= 0: from this many blocks of four contacts on (a step's
  // count, with simd_lanes or without), the step is compact: its blocks keep
  // what the sub-steps only read in floats (3,008 bytes instead of 4,640),
  // and the rows, the scalar update's too, hold those values rounded to
  // floats (a relative 6e-8), so the lanes still give the scalar update's
  // bits; 0: every step. Past about 2,000 blocks (9 MB of wide blocks) a
  // wide block's bytes cost more than a compact one's conversions
  // (docs/performance.md).
  int compact_blocks_from = 2000;
};

// The most sub-steps SoftStepSettings::substeps may ask for.
constexpr int kMaxSoftSubsteps = 64;

Status ValidateSoftStepSettings(const SoftStepSettings& settings);

struct WorldSettings {
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  // m/s^2, world frame (REP 103: z up)
  double time_step = 1.0 / 240.0;        // s, > 0
  // m; bounding boxes are fattened by this, and contact points are reported
  // while the surfaces are closer than this (at most a quarter of the
  // thinner body's thickness) plus the pair's motion in a step.
  double contact_margin = 0.005;
  // A body moving more than this fraction of its thickness in one step is
  // sampled along its path, so it cannot pass through anything (0, 1].
  double continuous_fraction = 0.25;
  // m; a manifold between two polyhedra is carried along with the bodies
  // instead of clipped again while their relative motion since it was
  // clipped moves no point by more than this (0: clip every step).
  double contact_reuse_distance = 1e-3;
  // rad; the most a body may turn in one step: a faster spin is scaled down
  // to it before the drift (Bullet caps a quarter turn per step the same
  // way). A body turning further within a step has contacts no step can
  // find, and a small one spun up by an off-centre push (a 4 cm cube under
  // 400 N m) would otherwise turn at 1e5 rad/s and fling what it touches at
  // km/s. In (0, pi]; at 240 Hz the default allows 377 rad/s.
  double max_turn_per_step = 1.5707963267948966;
  // Threads a step runs on, the caller's included, in [0, kMaxThreads]; 0:
  // one per core. The narrow phase's shape pairs and the resting solve's
  // islands are shared among them; every island is swept exactly as with
  // one thread, so the result is the same bit for bit for any count. 1 (the
  // default) starts no thread and is the reference path.
  int threads = 1;
  // The solver of the stages from velocities to positions (the contact
  // solve and the impacts); see MotionSolverKind.
  MotionSolverKind motion_solver = MotionSolverKind::kExact;
  // kExact's; kSoftStep reads collision_velocity_threshold and
  // contact_tolerance.
  SolverSettings solver;
  SoftStepSettings soft_step;  // kSoftStep's
  SleepSettings sleep;
};

Status ValidateWorldSettings(const WorldSettings& settings);

// Wall-clock time of each stage of the last World::Step, for profiling; the
// stages are the ones listed in World's private section.
struct StepProfile {
  double broad_phase_ms = 0.0;    // ms, stage 1
  double narrow_phase_ms = 0.0;   // ms, stage 2
  double contact_cache_ms = 0.0;  // ms, stage 3
  double solver_ms = 0.0;         // ms, stage 4 (collisions, forces, resting contact)
  double integrator_ms = 0.0;     // ms, stage 5
  std::size_t solver_points = 0;  // contact points handed to the solver
  int velocity_sweeps = 0;        // Gauss-Seidel sweeps of the resting solve's slowest island
  std::size_t velocity_row_updates = 0;  // row updates of those sweeps, all islands
  // Groups of islands the resting solve swept on threads of their own (1:
  // all on the caller's thread).
  int island_groups = 1;
  // Manifolds carried to the new poses (contact_reuse_distance) instead of
  // clipped, in stage 2.
  std::size_t reused_manifolds = 0;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_SETTINGS_H_
