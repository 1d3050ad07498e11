// The articulations of a world as one system: their models and states,
// their commands and servo gains, the touching pairs that involve a link,
// and their part of the step (the joint-space solve of stage 4 and the move
// of stage 5). The world owns the link bodies and orders the stages; the
// system reaches the world only through LinkBodies.
#ifndef RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SYSTEM_H_
#define RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SYSTEM_H_

#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "physics/articulation/articulation_dynamics.h"
#include "physics/articulation/articulation_solver.h"
#include "physics/articulation/free_motion.h"
#include "physics/contact/contact_cache.h"
#include "physics/solver/contact_reports.h"
#include "physics/world/step_context.h"
#include "physics/world/union_find.h"
#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::physics {

// What the articulation system needs of the world that holds its link
// bodies (WorldImpl implements it).
class LinkBodies {
 public:
  virtual Result<BodyId> CreateBody(const BodyDef& def) = 0;
  virtual Status DestroyBody(BodyId id) = 0;
  virtual BodyId BodyIdOf(std::uint32_t index) const = 0;
  // The body was teleported: what touched it wakes, its contacts are forgotten.
  virtual void RestartContacts(std::uint32_t body) = 0;

 protected:
  ~LinkBodies() = default;
};

// What a joint's row does; a joint has at most one row of each.
enum JointRowRole : int {
  kLowerLimitRow,
  kUpperLimitRow,
  kForwardSpeedRow,   // holds u <= the speed limit
  kBackwardSpeedRow,  // holds u >= -the speed limit
  kFrictionRow,
  kDriveRow,  // the command's motor or servo
  kJointRowRoles
};

// One joint row before it has a solver slot: the row on its dof `column`
// (sign: +1 pushes the joint forward), as ConstraintRow's fields.
struct JointRowSpec {
  int joint = -1;
  int column = 0;
  double sign = 1.0;
  RowKind kind = RowKind::kBounded;
  double target = 0.0;  // velocity units of the row
  double bound = 0.0;   // |impulse| <= bound (kBounded)
  double softness = 0.0;
  JointRowRole role = kDriveRow;
};

// An articulation in the world: its model, its state, and the state its
// constraint solve chose for the end of the step.
struct ArticulationEntry {
  ArticulationModel model;
  ArticulationState state;
  ArticulationState next;
  // Of `state` while `kinematics_current` (whoever sets `state` clears it);
  // of `next` while `next_kinematics_current` (the free step fills them).
  ArticulationKinematics kinematics;
  ArticulationKinematics next_kinematics;
  bool kinematics_current = false;
  bool next_kinematics_current = false;
  ServoGains gains;
  FreeMotionIntegrator free_motion;
  // Its rows' M^-1 J^T in a step of a large model (SetUpArticulation), and
  // the power method's vectors for its damping's fastest mode.
  ArticulatedResponse response;
  DampingModeScratch damping_modes;
  // The impulse each joint row ended its last step with, per joint and
  // JointRowRole (0 for a row it did not have): the next step's warm start.
  std::vector<double> joint_row_impulses;
  bool in_use = false;
  std::uint32_t generation = 0;
};

class ArticulationSystem {
 public:
  // `bodies` is the world's body slots, which the links are among.
  ArticulationSystem(std::vector<Body>* bodies, LinkBodies* world);

  // The public methods do what World's of the same name are documented to
  // do (articulation_system.cc).
  Result<ArticulationId> Create(const ArticulationDef& def);
  Status Destroy(ArticulationId id);
  bool IsValid(ArticulationId id) const;
  std::vector<BodyId> Links(ArticulationId id) const;
  std::vector<JointState> GetJointStates(ArticulationId id) const;
  Status SetJointStates(ArticulationId id, const std::vector<double>& positions,
                        const std::vector<double>& velocities);
  Status SetJointCommand(ArticulationId id, int joint, const JointCommand& command);
  Status SetServoGains(ArticulationId id, const ServoGains& gains);
  // Moves articulation `index` rigidly so that its link `link` takes this
  // pose and twist (World::SetState on a link).
  Status MoveWithLink(std::uint32_t index, const Pose& world_from_link, const Vec3& linear_velocity,
                      const Vec3& angular_velocity, int link);
  // Two links of one articulation that are not to collide.
  bool SkipsPair(const Body& a, const Body& b) const;
  // A body's collision group in the broad phase: its articulation's index
  // + 1 for a link of one that does not collide with itself, else 0 (none).
  std::uint32_t CollisionGroup(const Body& body) const;

  // The step (articulation_step.cc, link_contacts.cc). Stage 4: the touching pairs split into
  // the rigid bodies' (`rigid_pairs`, the contact solver's) and those with a
  // link (kept here), then one solve of the articulations with their rows.
  void TakeLinkPairs(const std::vector<ShapePairContact*>& touching,
                     std::vector<ShapePairContact*>* rigid_pairs);
  const std::vector<ShapePairContact*>& link_pairs() const { return link_pairs_; }
  void Solve(const StepContext& step);
  // The mean velocities over this step of a rigid body that a link struck
  // within it at t_c, (t_c v- + (dt - t_c) v+) / dt, with v- its velocity
  // before the impact and v+ after (linear, and angular). False for any
  // other body, which drifts as its solver integrates it; *linear and
  // *angular are then left as they are.
  bool StruckBodyMeanVelocity(std::uint32_t body, double dt, Vec3* linear, Vec3* angular) const;
  // Keeps the link pairs' impulses for the next warm start and reports
  // their points in *reports, after the rigid pairs'.
  void ReportContacts(const StepContext& step, ContactReports* reports);
  // Stage 5: each articulation takes the state its solve chose, and its
  // links follow.
  void Move();

 private:
  // The row solves' limits (projected Gauss-Seidel).
  static constexpr int kMaxSweeps = 200;
  static constexpr double kSweepTolerance = 1e-9;

  static void Teleported(ArticulationEntry* entry);
  // Places the links where entry.state says (from its kinematics, computed
  // if they are not current).
  void PlaceLinks(std::uint32_t index, bool restart);
  int SetUpArticulation(const StepContext& step, std::uint32_t index, bool touched);
  void AddArticulationRows(std::uint32_t index, int slot, const std::vector<JointRowSpec>& rows);
  // A link-contact row's sides read each articulation's solver slot and
  // its entry's kinematics (with Jacobians, for those with contacts).
  void AddLinkContactRows(const StepContext& step, const std::vector<int>& slot_of_articulation);
  int AddLinkPointRows(const StepContext& step, const std::vector<int>& slot_of_articulation,
                       const ShapePairContact& pair, int i);
  // A body's sides of a point's three rows, along `directions`.
  std::array<RowSide, 3> LinkContactSides(const std::vector<int>& slot_of_articulation,
                                          std::uint32_t index,
                                          const std::array<Vec3, 3>& directions, const Vec3& point);
  double StartPointVelocity(std::uint32_t index, const Vec3& direction, const Vec3& point) const;
  void BounceLinkContacts(const StepContext& step, const std::vector<int>& slot_of_articulation);
  std::vector<double> LinkImpactTimes(const StepContext& step,
                                      const std::vector<int>& slot_of_articulation);
  void FindApproachVelocities();
  void CapBounceEnergy(const std::vector<int>& slot_of_articulation);
  // Kinetic energies at the step's start pose.
  double LinkKineticEnergy(const ArticulationEntry& entry, const Eigen::VectorXd& u);
  static double BodyKineticEnergy(const Body& body, const Vec3& linear_velocity,
                                  const Vec3& angular_velocity);
  double SideApproachVelocity(const RowSide& side) const;
  double SideVelocityOnPath(const RowSide& side, double fraction,
                            const std::vector<Eigen::VectorXd>& start) const;
  double LinkPairImpactTime(const StepContext& step, const std::vector<int>& slot_of_articulation,
                            const ShapePairContact& pair, double closing_speed);
  Pose BodyPoseOnImpactPath(std::uint32_t index, const std::vector<int>& slot_of_articulation,
                            double t);
  void CorrectLinkPenetration(const StepContext& step,
                              const std::vector<int>& slot_of_articulation);
  void TakeUnpushedFreeSteps(const StepContext& step, const std::vector<int>& slot_of_articulation);
  void RecordJointEfforts(const StepContext& step);
  void TakeLinkSolveVelocities(const StepContext& step);

  std::vector<Body>& bodies_;
  LinkBodies& world_;
  std::vector<ArticulationEntry> articulations_;
  ArticulationSolver solver_;
  ArticulatedBodyScratch scratch_;               // SetUpArticulation's
  std::vector<JointRowSpec> joint_row_scratch_;  // SetUpArticulation's
  Eigen::VectorXd efforts_scratch_;              // SetUpArticulation's
  Eigen::VectorXd free_velocity_scratch_;        // SetUpArticulation's, u*
  std::vector<char> touched_scratch_;            // Solve's, per articulation
  std::vector<int> slot_scratch_;                // Solve's, per articulation
  // Solve's, per articulation: in the solve for its contacts alone, and
  // moved by its free step instead (TakeUnpushedFreeSteps).
  std::vector<char> contact_only_;
  std::vector<char> free_stepped_;
  std::vector<char> pushed_scratch_;  // TakeUnpushedFreeSteps', per slot
  Eigen::VectorXd acceleration_scratch_;
  std::vector<ShapePairContact*> link_pairs_;  // TakeLinkPairs'
  UnionFind link_islands_;                     // TakeLinkPairs' scratch
  // TakeLinkPairs' scratch: per body slot, its flags (counted; of a root,
  // the island touches a link), and per island root its size.
  std::vector<char> island_flags_;
  std::vector<std::uint32_t> island_sizes_;
  // Per link pair, the index of its first normal row, or -1.
  std::vector<int> link_pair_rows_;
  // The normal rows of link contacts penetrating beyond the slop, each with
  // the speed that removes position_correction of that depth in one step,
  // and the solver of their split impulse (CorrectLinkPenetration).
  std::vector<std::pair<int, double>> link_penetrations_;
  std::vector<std::size_t> bouncing_rows_;  // scratch of BounceLinkContacts
  // Per articulation slot, its velocity before the bouncing points'
  // impulses (LinkImpactTimes).
  std::vector<Eigen::VectorXd> approach_velocities_;
  // Per body slot of the solve, a rigid body's velocity before the bouncing
  // points' impulses and the time a link strikes it (+infinity when none
  // does); empty when no point bounced this step.
  struct BodyImpact {
    Vec3 linear_velocity = Vec3::Zero();
    Vec3 angular_velocity = Vec3::Zero();
    double time = std::numeric_limits<double>::infinity();
  };
  std::vector<BodyImpact> body_impacts_;
  // BodyPoseOnImpactPath's state and kinematics at a time of the path.
  ArticulationState impact_state_;
  ArticulationKinematics impact_kinematics_;
  // The rigid bodies' velocities of the link solve before its restitution
  // pass, per body slot; empty when no point bounced this step.
  std::vector<ArticulationSolver::BodySlot> solved_bodies_;
  // The same for the articulations' velocities per slot, and the bouncing
  // rows' impulses (CapBounceEnergy's).
  std::vector<Eigen::VectorXd> solved_articulations_;
  std::vector<double> solved_impulses_;
  std::vector<int> articulation_of_slot_;  // CapBounceEnergy's scratch
  ArticulationSolver pseudo_solver_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SYSTEM_H_
