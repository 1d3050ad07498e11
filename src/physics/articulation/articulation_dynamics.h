// The dynamics of one articulation in joint coordinates: forward kinematics,
// link Jacobians, the joint-space inertia matrix and the generalized forces
// (Featherstone 2008, "Rigid Body Dynamics Algorithms", chapter 6, the
// composite-rigid-body formulation M(q) u' = Q(q, u); its equations are in
// docs/design.md, "Articulated bodies").
#ifndef RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_DYNAMICS_H_
#define RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_DYNAMICS_H_

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/StdVector>

#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

using JacobianRows = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // linear (3) then angular (3)

// [v]x, the matrix of the cross product: Skew(v) w = v x w.
inline Mat3 Skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

struct ArticulationLink {
  std::uint32_t body = 0;                // the link's Body in the world
  int parent_joint = -1;                 // -1 for the base
  double mass = 0.0;                     // kg
  Vec3 com_link = Vec3::Zero();          // m, centre of mass in the link frame
  Mat3 inertia_link = Mat3::Identity();  // kg m^2, about the centre of mass, link frame
  Vec3 force = Vec3::Zero();   // N, world, applied over the next step at the centre of mass
  Vec3 torque = Vec3::Zero();  // N m, world
};

struct ArticulationJoint {
  JointDef def;
  int dof = -1;  // index into the joint velocities; -1 for a mimic joint
  JointCommand command;
  double effort = 0.0;  // N m or N transmitted in the last step
  // 1 + the sum of its mimics' squared multipliers: the generalized force on
  // its dof when it and each mimic exert the same effort (scaled).
  double effort_scale = 1.0;
};

// The state integrated over time: the base (its centre of mass and
// orientation, velocities when floating) and the joints' positions and
// velocities. u = (v_com, omega) of the base, when floating, then one
// velocity per joint degree of freedom.
struct ArticulationState {
  Vec3 base_com = Vec3::Zero();           // m, world
  Quat base_rotation = Quat::Identity();  // world_from_base link
  Eigen::VectorXd q;                      // joint dof positions, rad or m
  Eigen::VectorXd u;                      // base velocities (if floating), then joint dofs
};

struct ArticulationModel {
  std::vector<ArticulationLink> links;
  std::vector<ArticulationJoint> joints;
  bool fixed_base = true;
  bool self_collide = false;
  int base_dofs = 0;   // 6 when floating
  int joint_dofs = 0;  // movable joints that mimic none
  int DofCount() const { return base_dofs + joint_dofs; }
};

// Where every link is and how it moves, for one state.
struct ArticulationKinematics {
  std::vector<Pose> world_from_link;
  std::vector<Vec3> com_world;         // m
  std::vector<Mat3> inertia_world;     // kg m^2
  std::vector<Vec3> linear_velocity;   // m/s, of the centre of mass
  std::vector<Vec3> angular_velocity;  // rad/s
  std::vector<Vec3> joint_axis_world;
  std::vector<Vec3> joint_anchor_world;  // m, the joint frame's origin
  std::vector<double> joint_position;    // rad or m, every joint (mimics included)
  std::vector<double> joint_velocity;
  std::vector<JacobianRows> jacobian;  // per link: (v_com, omega) = J u
};

// Whether any joint has damping (B != 0).
bool AnyJointDamped(const ArticulationModel& model);

// The dof a joint's velocity comes from, and the factor: a mimic joint moves
// with its leader's dof, times its multiplier.
int DrivingDof(const ArticulationModel& model, int joint, double* factor);

// A point fixed to a link, and three directions: what a contact point's
// normal and friction rows read.
struct LinkPoint {
  int link = 0;
  Vec3 point = Vec3::Zero();            // m, world
  std::array<Vec3, 3> directions = {};  // world
};

// Per direction d, the row r with r . u = d . (velocity of the point): for
// each joint on the path from the link to the base, d . (s x (p - a)) for a
// turn about s through a, d . s for a slide (a mimic's on its leader's dof,
// times its multiplier); for a floating base, d on its centre's velocity
// and (p - c) x d on its angular velocity. O(depth) in one walk for the
// three, from the kinematics' poses; the links' dense Jacobians cost O(n^2)
// for one row.
void PointVelocityRows(const ArticulationModel& model, const ArticulationKinematics& kinematics,
                       const LinkPoint& at, std::array<Eigen::VectorXd, 3>* rows);

// A joint's position and velocity from the state (mimic joints follow their
// leader).
double JointPosition(const ArticulationModel& model, const ArticulationState& state, int joint);
double JointVelocity(const ArticulationModel& model, const ArticulationState& state, int joint);

// What ComputeKinematics fills: the links' poses and velocities always
// (O(n)), their dense Jacobians (6 x dofs each, O(n^2)) only for a row
// solve that needs them.
enum class KinematicsParts : std::uint8_t { kPosesAndVelocities, kWithJacobians };

// Forward kinematics and velocities, and the Jacobians if asked, by one
// pass from the base to the leaves. `jacobian` is left empty without them.
void ComputeKinematics(const ArticulationModel& model, const ArticulationState& state,
                       ArticulationKinematics* kinematics, KinematicsParts parts);

// The joint-space inertia M = sum_i J_i^T diag(m_i 1, I_i) J_i by the
// composite-rigid-body algorithm (Featherstone 2008, "Rigid Body Dynamics
// Algorithms", section 6.2, in world-frame vectors): the links of each
// subtree are merged into one body (mass, centre C, inertia I_C), and the
// entry of dofs d and e is the kinetic energy's bilinear form of their unit
// motions over the subtree both move, the deeper joint's: M v_d(C).v_e(C) +
// omega_d . I_C omega_e. O(n d) for n links of depth d, against O(n^3) for
// the sum over the links' Jacobians.
void JointSpaceInertia(const ArticulationModel& model, const ArticulationKinematics& kinematics,
                       Eigen::MatrixXd* mass);
// The same M as that sum of J_i^T diag(m_i 1, I_i) J_i over the links'
// Jacobians: the reference the tests compare JointSpaceInertia with.
void JointSpaceInertiaByJacobians(const ArticulationModel& model,
                                  const ArticulationKinematics& kinematics, Eigen::MatrixXd* mass);

// The joint-space inertia M (JointSpaceInertia), and the
// generalized force Q = sum_i J_i^T (m_i g + F_i - m_i a_i, T_i - I_i alpha_i
// - omega_i x I_i omega_i) + tau, where (a_i, alpha_i) are the link
// accelerations for u' = 0 (velocity products only) and tau the joints'
// efforts less their damping. `joint_efforts` is per dof.
struct JointSpaceDynamics {
  Eigen::MatrixXd mass;
  Eigen::VectorXd force;
};
void ComputeDynamics(const ArticulationModel& model, const ArticulationState& state,
                     const ArticulationKinematics& kinematics, const Vec3& gravity,
                     const Eigen::VectorXd& joint_efforts, JointSpaceDynamics* dynamics);

// One forward dynamics problem: u' = (M + h B)^-1 Q for the state, its
// kinematics (poses and velocities), and h = damping_step (0: the damping
// explicit in Q only; h > 0: also implicit over a step of h, as the
// velocity-level step takes it).
struct ForwardDynamicsInput {
  const ArticulationModel& model;
  const ArticulationState& state;
  const ArticulationKinematics& kinematics;
  const Vec3& gravity;                   // m/s^2
  const Eigen::VectorXd& joint_efforts;  // per dof, N m or N
  double damping_step = 0.0;             // s
};

// The articulated-body algorithm's buffers, kept from call to call so that
// a step allocates nothing once they have their model's size.
struct ArticulatedBodyScratch {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Vec3 origin = Vec3::Zero();                                 // O, m, world
  std::vector<Mat6, Eigen::aligned_allocator<Mat6>> inertia;  // per link, I^A about O
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> bias;     // per link, p^A
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> velocity;
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> product;           // c_i
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> acceleration;      // a_i
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> subspace;          // per joint, S
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> inertia_subspace;  // U = I^A S
  std::vector<double> pivot;                                           // D
  std::vector<double> remainder;                                       // u
  ArticulationKinematics kinematics;  // the composite-rigid-body path's
  void Prepare(const ForwardDynamicsInput& in);
};

// Whether the articulated-body algorithm applies: a tree whose every joint
// has its own dof. A mimic joint couples two dofs, which the recursion
// cannot express; such models take the composite-rigid-body path.
bool ArticulatedBodyApplies(const ArticulationModel& model);

// u' by the articulated-body algorithm (Featherstone 2008, section 7.3),
// O(n) (articulated_body_algorithm.cc). Only when ArticulatedBodyApplies.
void ArticulatedBodyForwardDynamics(const ForwardDynamicsInput& in, ArticulatedBodyScratch* scratch,
                                    Eigen::VectorXd* acceleration);
// u' = (M + h B)^-1 Q with M by the composite-rigid-body algorithm and a
// dense Cholesky factor, O(n d + n^3): any model, mimics included; the
// reference the tests compare the articulated-body algorithm with.
void CompositeRigidBodyForwardDynamics(const ForwardDynamicsInput& in,
                                       ArticulationKinematics* kinematics,
                                       Eigen::VectorXd* acceleration);
// The first where it applies, else the second.
void ForwardDynamics(const ForwardDynamicsInput& in, ArticulatedBodyScratch* scratch,
                     Eigen::VectorXd* acceleration);

// An articulation's response to generalized impulses, (M + h B)^-1 Q, in
// O(n) per call from the articulated-body inertias of one evaluation: the
// row solve's M^-1 J^T for a model too large for a dense factor, whose
// O(n^3) factor and O(n^2) per row would dominate its step
// (articulated_body_algorithm.cc). Only where ArticulatedBodyApplies.
class ArticulatedResponse {
 public:
  // Keeps U / D, 1 / D and S of every joint, and the base's articulated
  // inertia, from `scratch` right after ArticulatedBodyForwardDynamics of
  // `model` (with h as its damping_step).
  void Capture(const ArticulationModel& model, const ArticulatedBodyScratch& scratch);
  // response = (M + h B)^-1 force, force over the model's u and zero from
  // `extent` on (the joints past it are skipped on the way in).
  void Apply(const Eigen::VectorXd& force, Eigen::Index extent, Eigen::VectorXd* response);
  // Three at once, their recursions interleaved: about the time of one.
  void ApplyThree(const std::array<const Eigen::VectorXd*, 3>& forces, Eigen::Index extent,
                  const std::array<Eigen::VectorXd*, 3>& responses);

 private:
  using Vec6 = ArticulatedBodyScratch::Vec6;
  using Mat6 = ArticulatedBodyScratch::Mat6;
  template <int K>
  using Block = Eigen::Matrix<double, 6, K>;
  template <int K>
  using Blocks = std::vector<Block<K>, Eigen::aligned_allocator<Block<K>>>;
  // A joint's links and its column of u, packed for the passes.
  struct Edge {
    int parent = 0;
    int child = 0;
    int column = 0;
  };
  template <int K>
  void Passes(const std::array<const Eigen::VectorXd*, K>& forces, Eigen::Index extent,
              const std::array<Eigen::VectorXd*, K>& responses, Blocks<K>* bias,
              Blocks<K>* acceleration);

  int base_dofs_ = 0;
  int dof_count_ = 0;
  std::vector<Edge> edges_;                                     // per joint
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> subspace_;  // per joint, S
  std::vector<Vec6, Eigen::aligned_allocator<Vec6>> scaled_;    // U / D
  std::vector<double> inverse_pivot_;                           // 1 / D
  // I^A of a floating base; the identity's until captured, so that a copy
  // (the entries' vector growing) never reads an unset factor.
  Eigen::LLT<Mat6> base_inertia_{Mat6::Identity()};
  // The passes': per link, the biases p^A and the accelerations; per joint
  // and force, u.
  Blocks<1> bias_one_, acceleration_one_;
  Blocks<3> bias_three_, acceleration_three_;
  std::vector<double> remainder_;
};

// FastestDampingRate's vectors: B^1/2's diagonal, the power method's
// iterate, kept from call to call, and its image.
struct DampingModeScratch {
  Eigen::VectorXd root_damping;
  Eigen::VectorXd mode;
  Eigen::VectorXd image;
};

// lambda_max(M^-1 B), the fastest decay rate of the joints' damping B, from
// below, by the power method from scratch->mode (articulated_body_
// algorithm.cc). `response` is the articulation's response to M + h B.
double FastestDampingRate(const ArticulationModel& model, double h, ArticulatedResponse* response,
                          DampingModeScratch* scratch);

// The state advanced by h with velocities u: joint positions by h u, the
// base by h v and a turn of h omega.
ArticulationState Advance(const ArticulationModel& model, const ArticulationState& state,
                          const Eigen::VectorXd& u, double h);
// The same positions written into `out` (its u is left as it was), without
// allocating once `out` has the state's size. `u` may be out->u; `out` must
// not be `state`.
void AdvanceInto(const ArticulationModel& model, const ArticulationState& state,
                 const Eigen::VectorXd& u, double h, ArticulationState* out);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_ARTICULATION_ARTICULATION_DYNAMICS_H_
