// The step's contact reports, for both solvers and for the link contacts:
// the sleeping pairs' reports first, then one per solved point that
// touches or took a collision impulse, then the links'. Only the colliding
// ones are written when the step reports them (they go to the collision
// log too); the others are written when first read (Flush): most steps of
// a node that publishes at a tenth of its step rate are never read, and
// writing a report costs about what the solve of its point does (a
// 4,095-box pyramid: 10 % of the soft step).
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_REPORTS_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_REPORTS_H_

#include <array>
#include <cstdint>
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/solver/contact_solver.h"
#include "physics/world/step_context.h"
#include "physics/world/task_pool.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// What the reports are made of, all the world's.
struct ContactReportsWorld {
  const std::vector<Body>* bodies = nullptr;  // slots: ids and shapes
  const ContactSolver* solver = nullptr;      // the solver manifolds
  const ContactCache* contact_cache = nullptr;
  const WorldSettings* settings = nullptr;
};

class ContactReports {
 public:
  explicit ContactReports(const ContactReportsWorld& world);

  // The solved pairs' reports, `pairs` in the solver manifolds' order (a
  // manifold per pair), after the sleeping pairs'; each pair keeps its
  // points' impulses for the next step's warm start. `impacts_only`: a
  // time-of-impact sub-step's, whose manifolds replace the step's, reports
  // only its collisions, written at once.
  void ReportSolved(const std::vector<ShapePairContact*>& pairs, const StepContext& step,
                    bool impacts_only);
  // A resting report of point i of a pair from its cached impulses, with
  // `tangent` the basis of its normal (TangentBasis) that they are in.
  ContactReport MakeReport(const ShapePairContact& pair, int i, const std::array<Vec3, 2>& tangent,
                           const StepContext& step) const;
  // A report made outside the solver manifolds (a link's point), after the
  // others; a colliding one goes to the collision log too.
  void Append(const ContactReport& report);

  // Writes the reports ReportSolved left to be written when read: before
  // contacts() is read, and before a call changes the pairs or the bodies'
  // slots they are made of.
  void Flush(TaskPool* pool);
  // The last step's reports, written first if they are not yet.
  const std::vector<ContactReport>& contacts(TaskPool* pool) {
    Flush(pool);
    return contacts_;
  }
  // A new step's reports take the place of the last step's that nobody
  // read, which are then never written.
  void DiscardPending() { pending_.pending = false; }
  // Drops every report of body `index` (it was frozen), from the step's and
  // from the collision log; the sleeping pairs' are made afresh.
  void ForgetBody(std::uint32_t index, TaskPool* pool);
  // Drops every report and the collision log (the world restarts).
  void Clear();
  std::vector<ContactReport> TakeCollisionLog();

 private:
  std::size_t ReportSleeping(const StepContext& step);
  void Write(std::size_t m, const std::vector<ShapePairContact*>& pairs, double dt,
             bool impacts_only);

  const std::vector<Body>& bodies_;
  const ContactSolver& solver_;
  const ContactCache& contact_cache_;
  const WorldSettings& settings_;
  std::vector<ContactReport> contacts_;
  std::vector<ContactReport> collision_log_;
  // contacts_ begins with the reports of the sleeping pairs, made when
  // their list last changed (its version is kept here).
  std::uint64_t sleeping_version_ = ~std::uint64_t{0};
  std::size_t sleeping_count_ = 0;
  // ReportSolved's scratch: where each manifold's reports start, and
  // whether they hold a collision (those are written at once).
  std::vector<std::uint32_t> offsets_;
  std::vector<std::uint8_t> collided_;
  // What Flush needs of the last ReportSolved: its pairs (the touching
  // pairs without a link), its step and its kind.
  struct Pending {
    const std::vector<ShapePairContact*>* pairs = nullptr;
    double dt = 0.0;  // s
    bool impacts_only = false;
    bool pending = false;  // some reports are not written yet
  } pending_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_REPORTS_H_
