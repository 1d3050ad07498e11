// Forward dynamics in O(n): the articulated-body algorithm (Featherstone
// 2008, "Rigid Body Dynamics Algorithms", section 7.3, table 7.1), in
// spatial vectors of one frame: world axes about a point O, here the base's
// centre of mass (so that offsets stay small wherever the robot stands).
// A motion is m = (omega, v_O), the velocity of the body's point at O; a
// force is f = (n_O, f). In one fixed frame every transform is the identity:
//   pass 1 (out):  v_i = v_p + S_i qdot_i,  c_i = v_i x S_i qdot_i,
//                  p_i = v_i x* I_i v_i - f_ext,i;
//   pass 2 (in):   U_i = I^A_i S_i,  D_i = S_i . U_i + a_i,
//                  u_i = tau_i - S_i . p^A_i,
//                  I^A_p += I^A_i - U_i U_i^T / D_i,
//                  p^A_p += p^A_i + (I^A_i - U_i U_i^T / D_i) c_i + U_i u_i / D_i;
//   pass 3 (out):  a'_i = a_p + c_i,  qddot_i = (u_i - U_i . a'_i) / D_i,
//                  a_i = a'_i + S_i qddot_i,
// with a_0 = 0 for a fixed base and a_0 = -(I^A_0)^-1 p^A_0 for a floating
// one. A turning joint about unit s through p has S = (s, p x s) (relative
// to O), a sliding one S = (0, s). The armature a_i = h B_i makes the
// joints' damping implicit over a step h: the algorithm then solves
// (M + h B) u' = Q exactly, as a joint's rotor inertia would enter.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "physics/articulation/articulation_dynamics.h"

namespace rigid_body_sim::physics {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The spatial inertia about O of a body of mass m, centre c (relative to
// O) and inertia I_c about its centre: [I_c - m [c]x[c]x, m [c]x;
// -m [c]x, m 1] (Featherstone 2008, equation 2.63), with
// -[c]x[c]x = |c|^2 1 - c c^T.
void SpatialInertia(double mass, const Vec3& c, const Mat3& inertia_com, Mat6* inertia) {
  const Mat3 cx = mass * Skew(c);
  inertia->topLeftCorner<3, 3>() =
      inertia_com + mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  inertia->topRightCorner<3, 3>() = cx;
  inertia->bottomLeftCorner<3, 3>() = -cx;
  inertia->bottomRightCorner<3, 3>() = mass * Mat3::Identity();
}

// m1 x m2 = (w1 x w2, w1 x v2 + v1 x w2).
Vec6 CrossMotion(const Vec6& m1, const Vec6& m2) {
  Vec6 out;
  out.head<3>() = m1.head<3>().cross(m2.head<3>());
  out.tail<3>() = m1.head<3>().cross(m2.tail<3>()) + m1.tail<3>().cross(m2.head<3>());
  return out;
}

// m x* f = (w x n + v x f, w x f).
Vec6 CrossForce(const Vec6& m, const Vec6& f) {
  Vec6 out;
  out.head<3>() = m.head<3>().cross(f.head<3>()) + m.tail<3>().cross(f.tail<3>());
  out.tail<3>() = m.head<3>().cross(f.tail<3>());
  return out;
}

}  // namespace

bool AnyJointDamped(const ArticulationModel& model) {
  return std::any_of(model.joints.begin(), model.joints.end(),
                     [](const ArticulationJoint& joint) { return joint.def.damping > 0.0; });
}

bool ArticulatedBodyApplies(const ArticulationModel& model) {
  return std::all_of(model.joints.begin(), model.joints.end(),
                     [](const ArticulationJoint& joint) { return joint.dof >= 0; });
}

// Pass 1 and the bodies' own terms: spatial inertia, velocity, velocity
// product and bias force per link, all about O.
void ArticulatedBodyScratch::Prepare(const ForwardDynamicsInput& in) {
  const ArticulationModel& model = in.model;
  const ArticulationKinematics& k = in.kinematics;
  const std::size_t link_count = model.links.size();
  origin = in.state.base_com;
  inertia.resize(link_count);
  bias.resize(link_count);
  velocity.resize(link_count);
  product.resize(link_count);
  acceleration.resize(link_count);
  subspace.resize(model.joints.size());
  inertia_subspace.resize(model.joints.size());
  pivot.resize(model.joints.size());
  remainder.resize(model.joints.size());
  for (std::size_t i = 0; i < link_count; ++i) {
    const ArticulationLink& link = model.links[i];
    const Vec3 c = k.com_world[i] - origin;
    SpatialInertia(link.mass, c, k.inertia_world[i], &inertia[i]);
    const Vec3& omega = k.angular_velocity[i];
    const Vec3& v_com = k.linear_velocity[i];
    velocity[i].head<3>() = omega;
    velocity[i].tail<3>() = v_com - omega.cross(c);
    product[i].setZero();
    // The momentum I v about O, from the centre's: (I_c omega + c x m v_c, m v_c).
    Vec6 momentum;
    momentum.tail<3>() = link.mass * v_com;
    momentum.head<3>() = k.inertia_world[i] * omega + c.cross(momentum.tail<3>());
    const Vec3 force = link.mass * in.gravity + link.force;
    Vec6 external;
    external.head<3>() = link.torque + c.cross(force);
    external.tail<3>() = force;
    bias[i] = CrossForce(velocity[i], momentum) - external;
  }
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const JointDef& def = model.joints[j].def;
    Vec6& s = subspace[j];
    if (def.type == JointType::kPrismatic) {
      s << Vec3::Zero(), k.joint_axis_world[j];
    } else {
      s << k.joint_axis_world[j], (k.joint_anchor_world[j] - origin).cross(k.joint_axis_world[j]);
    }
    product[def.child_link] = CrossMotion(velocity[def.child_link], s * k.joint_velocity[j]);
  }
}

void ArticulatedBodyForwardDynamics(const ForwardDynamicsInput& in, ArticulatedBodyScratch* scratch,
                                    Eigen::VectorXd* acceleration) {
  const ArticulationModel& model = in.model;
  ArticulatedBodyScratch& s = *scratch;
  s.Prepare(in);
  // Pass 2, from the leaves in: a joint comes after its parent link's joint.
  for (std::size_t j = model.joints.size(); j-- > 0;) {
    const ArticulationJoint& joint = model.joints[j];
    const int child = joint.def.child_link;
    const int parent = joint.def.parent_link;
    const int column = model.base_dofs + joint.dof;
    const double tau = in.joint_efforts[joint.dof] - joint.def.damping * in.state.u[column];
    const Vec6& subspace = s.subspace[j];
    Vec6& inertia_subspace = s.inertia_subspace[j];
    inertia_subspace.noalias() = s.inertia[child] * subspace;
    s.pivot[j] = subspace.dot(inertia_subspace) + in.damping_step * joint.def.damping;
    s.remainder[j] = tau - subspace.dot(s.bias[child]);
    // A fixed base's articulated inertia and bias are never read.
    if (parent == 0 && model.base_dofs == 0) continue;
    const Vec6 scaled = inertia_subspace / s.pivot[j];
    Mat6& articulated = s.inertia[child];
    articulated.noalias() -= scaled * inertia_subspace.transpose();
    s.inertia[parent] += articulated;
    s.bias[parent] += s.bias[child] + articulated * s.product[child] + scaled * s.remainder[j];
  }
  acceleration->resize(model.DofCount());
  if (model.base_dofs == 6) {
    s.acceleration[0] = -s.inertia[0].llt().solve(s.bias[0]);
    // The base's u is (v_com, omega), and O is its centre of mass: the
    // centre's acceleration is a_O + omega x v_com (a body point at O).
    const Vec3 omega = in.kinematics.angular_velocity[0];
    acceleration->head<3>() =
        s.acceleration[0].tail<3>() + omega.cross(in.kinematics.linear_velocity[0]);
    acceleration->segment<3>(3) = s.acceleration[0].head<3>();
  } else {
    s.acceleration[0].setZero();
  }
  // Pass 3, from the base out.
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const ArticulationJoint& joint = model.joints[j];
    const int child = joint.def.child_link;
    const Vec6 reached = s.acceleration[joint.def.parent_link] + s.product[child];
    const double qddot = (s.remainder[j] - s.inertia_subspace[j].dot(reached)) / s.pivot[j];
    s.acceleration[child] = reached + s.subspace[j] * qddot;
    (*acceleration)[model.base_dofs + joint.dof] = qddot;
  }
}

void ArticulatedResponse::Capture(const ArticulationModel& model,
                                  const ArticulatedBodyScratch& scratch) {
  base_dofs_ = model.base_dofs;
  dof_count_ = model.DofCount();
  const std::size_t joints = model.joints.size();
  edges_.resize(joints);
  scaled_.resize(joints);
  inverse_pivot_.resize(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const ArticulationJoint& joint = model.joints[j];
    edges_[j] = {joint.def.parent_link, joint.def.child_link, model.base_dofs + joint.dof};
    inverse_pivot_[j] = 1.0 / scratch.pivot[j];
    scaled_[j] = scratch.inertia_subspace[j] * inverse_pivot_[j];
  }
  subspace_.assign(scratch.subspace.begin(), scratch.subspace.end());
  if (model.base_dofs == 6) base_inertia_.compute(scratch.inertia[0]);
  const std::size_t links = model.links.size();
  bias_one_.resize(links);
  acceleration_one_.resize(links);
  bias_three_.resize(links);
  acceleration_three_.resize(links);
  remainder_.resize(3 * joints);
}

void ArticulatedResponse::Apply(const Eigen::VectorXd& force, Eigen::Index extent,
                                Eigen::VectorXd* response) {
  Passes<1>({&force}, extent, {response}, &bias_one_, &acceleration_one_);
}

void ArticulatedResponse::ApplyThree(const std::array<const Eigen::VectorXd*, 3>& forces,
                                     Eigen::Index extent,
                                     const std::array<Eigen::VectorXd*, 3>& responses) {
  Passes<3>(forces, extent, responses, &bias_three_, &acceleration_three_);
}

// The articulated-body algorithm's passes 2 and 3 with every velocity and
// gravity zero, so that c_i = 0 and p_i = -f_i: only the generalized force
// Q drives them, and the inertias (U, D, I^A_0) are the evaluation's:
//   pass 2 (in):   u_i = Q_i - S_i . p_i,  p_p += p_i + (U_i / D_i) u_i;
//   pass 3 (out):  qddot_i = u_i / D_i - (U_i / D_i) . a_p,
//                  a_i = a_p + S_i qddot_i,
// with a_0 = -(I^A_0)^-1 p_0 for a floating base, whose Q is (f, n), its
// force and its torque about its centre, in the order of its u = (v_com,
// omega). The result is (M + h B)^-1 Q exactly (Featherstone 2008, section
// 7.3; the same passes give the test-impulse responses of Mirtich 1996,
// "Impulse-based Dynamic Simulation of Rigid Body Systems", section 4.4).
// K forces go through together: a chain's passes are one long dependency
// chain, and K of them interleaved fill the time its latency leaves.
// Joints are numbered parents first and their columns follow their order,
// so a force zero from column `extent` on leaves every joint whose column
// is past it with u = 0 and p = 0 on its child: pass 2 starts below them.
template <int K>
void ArticulatedResponse::Passes(const std::array<const Eigen::VectorXd*, K>& forces,
                                 Eigen::Index extent,
                                 const std::array<Eigen::VectorXd*, K>& responses, Blocks<K>* bias,
                                 Blocks<K>* acceleration) {
  const bool floating = base_dofs_ == 6;
  Blocks<K>& p = *bias;
  Blocks<K>& a = *acceleration;
  for (Block<K>& block : p) block.setZero();
  std::size_t first_zero = edges_.size();
  while (first_zero > 0 && edges_[first_zero - 1].column >= extent) --first_zero;
  std::fill(remainder_.begin() + K * first_zero, remainder_.begin() + K * edges_.size(), 0.0);
  if (floating) {
    for (int k = 0; k < K; ++k) {
      p[0].col(k).template head<3>() = -forces[k]->template segment<3>(3);
      p[0].col(k).template tail<3>() = -forces[k]->template head<3>();
    }
  }
  for (std::size_t j = first_zero; j-- > 0;) {
    const Edge& edge = edges_[j];
    Eigen::Matrix<double, 1, K> u = -subspace_[j].transpose() * p[edge.child];
    for (int k = 0; k < K; ++k) u[k] += (*forces[k])[edge.column];
    Eigen::Map<Eigen::Matrix<double, 1, K>> stored(&remainder_[K * j]);
    stored = u;
    if (edge.parent == 0 && !floating) continue;
    p[edge.parent] += p[edge.child] + scaled_[j] * u;
  }
  for (int k = 0; k < K; ++k) responses[k]->resize(dof_count_);
  if (floating) {
    a[0] = -base_inertia_.solve(p[0]);
    for (int k = 0; k < K; ++k) {
      responses[k]->template head<3>() = a[0].col(k).template tail<3>();
      responses[k]->template segment<3>(3) = a[0].col(k).template head<3>();
    }
  } else {
    a[0].setZero();
  }
  for (std::size_t j = 0; j < edges_.size(); ++j) {
    const Edge& edge = edges_[j];
    const Eigen::Matrix<double, 1, K> qddot =
        Eigen::Map<const Eigen::Matrix<double, 1, K>>(&remainder_[K * j]) * inverse_pivot_[j] -
        scaled_[j].transpose() * a[edge.parent];
    a[edge.child] = a[edge.parent] + subspace_[j] * qddot;
    for (int k = 0; k < K; ++k) (*responses[k])[edge.column] = qddot[k];
  }
}

// The response to M + h B gives the generalized eigenvalues mu of
// B x = mu (M + h B) x, and lambda = mu / (1 - h mu) those of M^-1 B. mu_max
// is the largest eigenvalue of the symmetric positive semidefinite
// A = B^1/2 (M + h B)^-1 B^1/2, found by the power method (Golub and Van
// Loan 2013, "Matrix Computations", section 7.3.1) from the last call's
// vector: its Rayleigh quotients x . A x rise to mu_max from below, four
// iterations a call.
double FastestDampingRate(const ArticulationModel& model, double h, ArticulatedResponse* response,
                          DampingModeScratch* scratch) {
  constexpr int kIterations = 4;
  const Eigen::Index n = model.DofCount();
  Eigen::VectorXd& root = scratch->root_damping;
  Eigen::VectorXd& mode = scratch->mode;
  Eigen::VectorXd& image = scratch->image;
  root.setZero(n);
  for (const ArticulationJoint& joint : model.joints) {
    root[model.base_dofs + joint.dof] = std::sqrt(joint.def.damping);
  }
  if (mode.size() != n || !(mode.squaredNorm() > 0.0)) mode = root;
  double mu = 0.0;
  for (int i = 0; i < kIterations && mode.squaredNorm() > 0.0; ++i) {
    mode /= mode.norm();               // x
    image = root.cwiseProduct(mode);   // B^1/2 x
    response->Apply(image, n, &mode);  // (M + h B)^-1 B^1/2 x
    mu = image.dot(mode);              // x . A x
    mode.array() *= root.array();      // A x
  }
  if (!(h * mu < 1.0)) return std::numeric_limits<double>::infinity();
  return mu / (1.0 - h * mu);
}

void CompositeRigidBodyForwardDynamics(const ForwardDynamicsInput& in,
                                       ArticulationKinematics* kinematics,
                                       Eigen::VectorXd* acceleration) {
  ComputeKinematics(in.model, in.state, kinematics, KinematicsParts::kWithJacobians);
  JointSpaceDynamics dynamics;
  ComputeDynamics(in.model, in.state, *kinematics, in.gravity, in.joint_efforts, &dynamics);
  for (const ArticulationJoint& joint : in.model.joints) {
    if (joint.dof < 0) continue;
    const int column = in.model.base_dofs + joint.dof;
    dynamics.mass(column, column) += in.damping_step * joint.def.damping;
  }
  *acceleration = dynamics.mass.llt().solve(dynamics.force);
}

void ForwardDynamics(const ForwardDynamicsInput& in, ArticulatedBodyScratch* scratch,
                     Eigen::VectorXd* acceleration) {
  if (ArticulatedBodyApplies(in.model)) {
    ArticulatedBodyForwardDynamics(in, scratch, acceleration);
  } else {
    CompositeRigidBodyForwardDynamics(in, &scratch->kinematics, acceleration);
  }
}

}  // namespace rigid_body_sim::physics
