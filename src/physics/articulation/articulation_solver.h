// The constraint solve of the articulations: contact points on their links,
// joint limits, servos, motors and joint friction, as rows of one
// complementarity problem in the joint-space velocities, solved by projected
// Gauss-Seidel (docs/design.md, "Articulated bodies").
//
// A row k has a Jacobian J_k over the velocities of the articulations and
// rigid bodies it touches, and an impulse lambda_k. Its velocity is
// v_k = J_k u. The effect of an impulse is u += M^-1 J_k^T lambda_k, made
// once per row and step (for an articulation, the dense solve with the
// joint-space inertia's factor, or above 24 dofs the articulated-body
// passes of ArticulatedResponse; for a rigid body, d/m and I^-1 (r x d)),
// so a sweep costs O(dofs) per row. This is the generalized form of the contact
// problem of Baraff 1996, "Linear-Time Dynamics using Lagrange Multipliers",
// section 7 (contact and joint limits as unilateral rows), solved with the
// Delassus operator J M^-1 J^T applied implicitly (Erleben 2007,
// "Velocity-based shock propagation for multibody dynamics animation",
// section 3, projected Gauss-Seidel over generalized velocities).
#ifndef RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SOLVER_H_
#define RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SOLVER_H_

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "physics/articulation/articulation_dynamics.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// One side of a row: an articulation's dense Jacobian row, or a rigid body's
// direction at a lever arm, or nothing (a static or sleeping body).
struct RowSide {
  enum class Kind : std::uint8_t { kNone, kArticulation, kBody };
  Kind kind = Kind::kNone;
  int slot = -1;             // index of the articulation or body slot
  Eigen::VectorXd jacobian;  // articulation: J_k over its u
  Eigen::VectorXd response;  // articulation: M^-1 J_k^T
  // articulation: J_k's entries from here on are zero (a link's row reaches
  // only the columns of the joints on its path, all before its own).
  Eigen::Index extent = 0;
  Vec3 linear = Vec3::Zero();            // body: d
  Vec3 angular = Vec3::Zero();           // body: r x d
  Vec3 linear_response = Vec3::Zero();   // body: d / m
  Vec3 angular_response = Vec3::Zero();  // body: I^-1 (r x d)
};

enum class RowKind : std::uint8_t {
  kBounded,  // lower <= lambda <= upper; v -> target (soft when softness > 0)
  kNormal,   // lambda >= 0, v >= target, lambda (v - target) = 0
  kTangent,  // friction, with the next row its pair: |(l_t0, l_t1)| <= mu l_normal
};

struct ConstraintRow {
  RowSide a;
  RowSide b;
  RowKind kind = RowKind::kBounded;
  double target = 0.0;                                      // velocity units of the row
  double lower = -std::numeric_limits<double>::infinity();  // impulse
  double upper = std::numeric_limits<double>::infinity();
  // gamma of a soft constraint: v + gamma lambda -> target (Catto 2011,
  // "Soft Constraints", GDC; the constraint force mixing of ODE).
  double softness = 0.0;
  int normal_row = -1;     // kTangent: its normal row
  double friction = 0.0;   // kTangent: mu
  double impulse = 0.0;    // lambda, warm start in, result out
  bool colliding = false;  // a contact point classified colliding
  // kNormal of a contact point still apart that closes within the step
  // faster than the collision threshold: -e v-, the v+ it leaves with once
  // its row has stopped it (impulse > 0). 0: no bounce.
  double bounce = 0.0;
  double restitution = 0.0;  // kNormal of a contact point: e of its materials
  // A joint's own row (limit, servo, motor, friction): whose, and the sign
  // its impulse has as the joint's effort.
  int articulation = -1;
  int joint = -1;
  int joint_role = -1;  // its JointRowRole (articulation_system.h)
  double joint_sign = 1.0;
  double inverse_mass = 0.0;  // 1 / (J M^-1 J^T + gamma), set by Solve
};

class ArticulationSolver {
 public:
  struct BodySlot {
    std::uint32_t body = 0;
    Vec3 linear_velocity = Vec3::Zero();
    Vec3 angular_velocity = Vec3::Zero();
    double inverse_mass = 0.0;
    Mat3 inverse_inertia_world = Mat3::Zero();
  };
  // An articulation's u and how M^-1 is applied to its rows: the factor of
  // its joint-space inertia, or, where `response` is set, the articulated-
  // body passes (ArticulatedResponse), which must outlive the solve.
  struct ArticulationSlot {
    Eigen::VectorXd u;
    std::optional<Eigen::LLT<Eigen::MatrixXd>> mass;
    ArticulatedResponse* response = nullptr;
  };

  void Reset();
  int AddArticulation(const Eigen::VectorXd& u, const Eigen::MatrixXd& mass);
  // As above, with the joint-space inertia already factored.
  int AddArticulation(const Eigen::VectorXd& u, const Eigen::LLT<Eigen::MatrixXd>& mass);
  // With its rows' responses from the articulated-body passes, O(n) each.
  int AddArticulation(const Eigen::VectorXd& u, ArticulatedResponse* response);
  // With the inertia of another solver's `slot` and velocities `u`.
  int AddArticulationLike(const Eigen::VectorXd& u, const ArticulationSlot& slot);
  // The slot of a rigid body, added once.
  int BodySlotOf(const BodySlot& body);
  // The slot of body `body` in this solve, or -1.
  int SlotOfBody(std::uint32_t body) const {
    return body < slot_of_body_.size() ? slot_of_body_[body] : -1;
  }
  RowSide ArticulationSide(int slot, const Eigen::VectorXd& jacobian) const;
  // Three sides at once (a contact point's normal and tangent rows): with
  // the articulated-body passes, their responses in one fused pass.
  std::array<RowSide, 3> ArticulationSides(int slot,
                                           std::array<Eigen::VectorXd, 3> jacobians) const;
  RowSide BodySide(int slot, const Vec3& direction, const Vec3& lever_arm) const;
  int AddRow(ConstraintRow row);

  // When the sweeps of Solve stop.
  struct SweepLimits {
    int max_sweeps = 0;
    double tolerance = 0.0;  // of an impulse's change, relative to the largest impulse
    // m/s; > 0: a contact point's rows are judged instead by the velocity
    // their change makes, |d lambda| J M^-1 J^T, as the rigid solver
    // judges its points (SolverSettings::velocity_tolerance).
    double contact_speed = 0.0;
    // Rows between rigid bodies alone (of an island a link touches) are
    // swept at most this often, as the rigid solver sweeps its points
    // (SolverSettings::velocity_iterations); later sweeps hold them, and a
    // contact the link rows then push further is held out of the body by
    // the split impulse beyond the slop, as the rigid solver holds it.
    int rigid_sweeps = std::numeric_limits<int>::max();
  };
  // Projected Gauss-Seidel until no impulse changes by more than
  // `tolerance` (relative to its size) or `max_sweeps`. Returns the sweeps.
  int Solve(int max_sweeps, double tolerance) { return Solve(SweepLimits{max_sweeps, tolerance}); }
  int Solve(const SweepLimits& limits);
  // Further sweeps over the given rows only (none a tangent), the other
  // rows' impulses held; returns the sweeps.
  int SweepRows(const std::vector<std::size_t>& rows, int max_sweeps, double tolerance);
  // v_k = J_k u with the current velocities.
  double RowVelocity(const ConstraintRow& row) const;

  std::vector<ConstraintRow>& rows() { return rows_; }
  std::vector<ArticulationSlot>& articulations() { return articulations_; }
  std::vector<BodySlot>& bodies() { return bodies_; }
  const std::vector<BodySlot>& bodies() const { return bodies_; }

 private:
  double SideVelocity(const RowSide& side) const;
  double SideResponse(const RowSide& side) const;  // J M^-1 J^T of the side
  void ApplyImpulse(const ConstraintRow& row, double impulse);
  double ArticulationVelocity(const RowSide& side) const;
  void ApplyToArticulation(const RowSide& side, double impulse);
  // One projected Gauss-Seidel update of a normal or bounded row; returns
  // |change of its impulse|.
  double UpdateRow(ConstraintRow* row);
  // The same for a point's two friction rows together; `speed` gets the
  // larger of the velocities their changes make.
  double UpdateFriction(std::size_t k, double* speed = nullptr);
  struct SweepChange {
    double largest = 0.0;  // N s, the largest change of an impulse judged by size
    double fastest = 0.0;  // m/s, the largest velocity change of a row judged by speed
    double scale = 0.0;    // N s, the largest normal or bounded impulse
  };
  SweepChange Sweep(const std::vector<std::size_t>& swept, bool by_speed);
  double HoldRigidRows(std::vector<std::size_t>* swept) const;

  std::vector<ArticulationSlot> articulations_;
  std::vector<BodySlot> bodies_;
  std::vector<int> slot_of_body_;
  std::vector<ConstraintRow> rows_;
  std::vector<std::size_t> swept_scratch_;  // Solve's rows
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_SOLVER_H_
