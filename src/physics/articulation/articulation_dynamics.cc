#include "physics/articulation/articulation_dynamics.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

namespace rigid_body_sim::physics {
namespace {

// The child link frame in the joint frame: a turn about the axis or a slide
// along it.
Pose JointMotion(const JointDef& def, double position) {
  if (def.type == JointType::kPrismatic) return Pose{def.axis * position, Quat::Identity()};
  return Pose{Vec3::Zero(), Quat(Eigen::AngleAxisd(position, def.axis))};
}

}  // namespace

int DrivingDof(const ArticulationModel& model, int joint, double* factor) {
  const ArticulationJoint& j = model.joints[joint];
  if (j.dof >= 0) {
    *factor = 1.0;
    return j.dof;
  }
  *factor = j.def.mimic_multiplier;
  return model.joints[j.def.mimic_joint].dof;
}

void PointVelocityRows(const ArticulationModel& model, const ArticulationKinematics& k,
                       const LinkPoint& at, std::array<Eigen::VectorXd, 3>* rows) {
  for (Eigen::VectorXd& row : *rows) row.setZero(model.DofCount());
  for (int link = at.link; model.links[link].parent_joint >= 0;) {
    const int j = model.links[link].parent_joint;
    const JointDef& def = model.joints[j].def;
    double factor = 1.0;
    const int column = model.base_dofs + DrivingDof(model, j, &factor);
    const Vec3& axis = k.joint_axis_world[j];
    const Vec3 moved = def.type == JointType::kPrismatic
                           ? axis
                           : Vec3(axis.cross(at.point - k.joint_anchor_world[j]));
    for (int r = 0; r < 3; ++r) (*rows)[r][column] += factor * at.directions[r].dot(moved);
    link = def.parent_link;
  }
  if (model.base_dofs == 6) {
    const Vec3 lever = at.point - k.com_world[0];
    for (int r = 0; r < 3; ++r) {
      (*rows)[r].head<3>() = at.directions[r];
      (*rows)[r].segment<3>(3) = lever.cross(at.directions[r]);
    }
  }
}

double JointPosition(const ArticulationModel& model, const ArticulationState& state, int joint) {
  const ArticulationJoint& j = model.joints[joint];
  if (j.dof >= 0) return state.q[j.dof];
  const ArticulationJoint& leader = model.joints[j.def.mimic_joint];
  return j.def.mimic_multiplier * state.q[leader.dof] + j.def.mimic_offset;
}

double JointVelocity(const ArticulationModel& model, const ArticulationState& state, int joint) {
  double factor = 1.0;
  const int dof = DrivingDof(model, joint, &factor);
  return factor * state.u[model.base_dofs + dof];
}

// Forward kinematics (Featherstone 2008, section 4.1, the link poses from
// the parent's by the joint transform) with the link velocities
// omega_c = omega_p + s qdot, v_c = v_p + omega_p x (c_c - c_p) + (s x
// (c_c - p) or s) qdot, and the same recursion for the Jacobian columns.
void ComputeKinematics(const ArticulationModel& model, const ArticulationState& state,
                       ArticulationKinematics* k, KinematicsParts parts) {
  const std::size_t link_count = model.links.size();
  const std::size_t joint_count = model.joints.size();
  const int n = model.DofCount();
  const bool jacobians = parts == KinematicsParts::kWithJacobians;
  k->world_from_link.resize(link_count);
  k->com_world.resize(link_count);
  k->inertia_world.resize(link_count);
  k->linear_velocity.resize(link_count);
  k->angular_velocity.resize(link_count);
  k->jacobian.resize(jacobians ? link_count : 0);
  k->joint_axis_world.resize(joint_count);
  k->joint_anchor_world.resize(joint_count);
  k->joint_position.resize(joint_count);
  k->joint_velocity.resize(joint_count);

  const ArticulationLink& base = model.links[0];
  const Mat3 base_rotation = state.base_rotation.toRotationMatrix();
  k->world_from_link[0] = Pose{state.base_com - base_rotation * base.com_link, state.base_rotation};
  k->com_world[0] = state.base_com;
  k->linear_velocity[0].setZero();
  k->angular_velocity[0].setZero();
  if (model.base_dofs == 6) {
    k->linear_velocity[0] = state.u.head<3>();
    k->angular_velocity[0] = state.u.segment<3>(3);
  }
  if (jacobians) {
    k->jacobian[0].setZero(6, n);
    if (model.base_dofs == 6) {
      k->jacobian[0].block<3, 3>(0, 0).setIdentity();
      k->jacobian[0].block<3, 3>(3, 3).setIdentity();
    }
  }
  for (std::size_t j = 0; j < joint_count; ++j) {
    const ArticulationJoint& joint = model.joints[j];
    const int parent = joint.def.parent_link;
    const int child = joint.def.child_link;
    const double position = JointPosition(model, state, static_cast<int>(j));
    const Pose world_from_joint = k->world_from_link[parent] * joint.def.parent_from_joint;
    k->world_from_link[child] = world_from_joint * JointMotion(joint.def, position);
    k->com_world[child] = k->world_from_link[child] * model.links[child].com_link;
    const Vec3 axis = world_from_joint.rotation * joint.def.axis;
    const Vec3 lever = k->com_world[child] - world_from_joint.translation;
    const Vec3 reach = k->com_world[child] - k->com_world[parent];
    const double velocity = JointVelocity(model, state, static_cast<int>(j));
    const bool slides = joint.def.type == JointType::kPrismatic;
    k->joint_axis_world[j] = axis;
    k->joint_anchor_world[j] = world_from_joint.translation;
    k->joint_position[j] = position;
    k->joint_velocity[j] = velocity;
    const Vec3& w_p = k->angular_velocity[parent];
    k->angular_velocity[child] = slides ? w_p : Vec3(w_p + axis * velocity);
    k->linear_velocity[child] = k->linear_velocity[parent] + w_p.cross(reach) +
                                (slides ? axis : Vec3(axis.cross(lever))) * velocity;
    if (!jacobians) continue;
    // J_c = [J_v,p - [c_c - c_p]x J_w,p ; J_w,p] plus the joint's column.
    const JacobianRows& jp = k->jacobian[parent];
    JacobianRows& jc = k->jacobian[child];
    jc = jp;
    jc.topRows<3>() -= Skew(reach) * jp.bottomRows<3>();
    double factor = 1.0;
    const int column = model.base_dofs + DrivingDof(model, static_cast<int>(j), &factor);
    if (slides) {
      jc.block<3, 1>(0, column) += factor * axis;
    } else {
      jc.block<3, 1>(0, column) += factor * axis.cross(lever);
      jc.block<3, 1>(3, column) += factor * axis;
    }
  }
  for (std::size_t i = 0; i < link_count; ++i) {
    const Mat3 rotation = k->world_from_link[i].rotation.toRotationMatrix();
    k->inertia_world[i] = rotation * model.links[i].inertia_link * rotation.transpose();
  }
}

void JointSpaceInertiaByJacobians(const ArticulationModel& model, const ArticulationKinematics& k,
                                  Eigen::MatrixXd* mass) {
  const int n = model.DofCount();
  mass->setZero(n, n);
  Eigen::Matrix<double, 6, Eigen::Dynamic> weighted(6, n);
  for (std::size_t i = 0; i < model.links.size(); ++i) {
    const JacobianRows& jacobian = k.jacobian[i];
    weighted.topRows<3>() = model.links[i].mass * jacobian.topRows<3>();
    weighted.bottomRows<3>() = k.inertia_world[i] * jacobian.bottomRows<3>();
    mass->noalias() += jacobian.transpose() * weighted;
  }
}

namespace {

// A set of links as one rigid body: its mass, centre of mass and inertia
// about that centre, world frame.
struct Composite {
  double mass = 0.0;            // kg
  Vec3 com = Vec3::Zero();      // m
  Mat3 inertia = Mat3::Zero();  // kg m^2
};

// m ((r.r) 1 - r r^T): the inertia a point mass m at r adds about the origin
// (the parallel-axis theorem).
Mat3 ParallelAxis(double mass, const Vec3& r) {
  return mass * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
}

// Adds `part` to `whole`, both about their own centres of mass.
void Merge(const Composite& part, Composite* whole) {
  const double mass = whole->mass + part.mass;
  if (mass <= 0.0) return;
  const Vec3 com = (whole->mass * whole->com + part.mass * part.com) / mass;
  whole->inertia += part.inertia + ParallelAxis(whole->mass, whole->com - com) +
                    ParallelAxis(part.mass, part.com - com);
  whole->mass = mass;
  whole->com = com;
}

// One unit motion of a whole subtree: its angular velocity, and the
// velocity of the point x: turning about `axis` through `anchor`, or
// sliding along `axis`.
struct UnitMotion {
  Vec3 axis = Vec3::Zero();
  Vec3 anchor = Vec3::Zero();
  bool turns = false;
  Vec3 AngularVelocity() const { return turns ? axis : Vec3::Zero(); }
  Vec3 VelocityAt(const Vec3& x) const { return turns ? Vec3(axis.cross(x - anchor)) : axis; }
};

// u_1^T M u_2 over a composite body that both unit motions move is
// M v_1(C).v_2(C) + omega_1 . I_C omega_2 (the kinetic energy's bilinear
// form; the terms linear in the links' offsets from C sum to zero). With
// the second motion's momentum made once, linear p = M v_2(C) and angular
// L = I_C omega_2 about C, it is v_1(C).p + omega_1.L: one cross product per
// ancestor (Featherstone 2008, section 6.2: the composite body's force
// f = I^c S_2 projected on S_1).
struct Momentum {
  Vec3 linear;   // kg m/s
  Vec3 angular;  // kg m^2/s, about the composite's centre of mass
};
Momentum UnitMomentum(const Composite& body, const UnitMotion& motion) {
  return {body.mass * motion.VelocityAt(body.com), body.inertia * motion.AngularVelocity()};
}
double MotionProduct(const Composite& body, const UnitMotion& first, const Momentum& second) {
  return first.VelocityAt(body.com).dot(second.linear) +
         first.AngularVelocity().dot(second.angular);
}

// Adds value to M(row, column) and, off the diagonal or for two distinct
// motions of one dof (a mimic and its leader), to M(column, row).
void AddSymmetric(int row, int column, double value, bool distinct, Eigen::MatrixXd* mass) {
  (*mass)(row, column) += value;
  if (row != column || distinct) (*mass)(column, row) += value;
}

}  // namespace

void JointSpaceInertia(const ArticulationModel& model, const ArticulationKinematics& k,
                       Eigen::MatrixXd* mass) {
  const int n = model.DofCount();
  mass->setZero(n, n);
  // Each link's subtree as one body, from the leaves in (a joint comes after
  // its parent link's joint).
  std::vector<Composite> subtree(model.links.size());
  for (std::size_t i = 0; i < model.links.size(); ++i) {
    subtree[i] = Composite{model.links[i].mass, k.com_world[i], k.inertia_world[i]};
  }
  for (std::size_t j = model.joints.size(); j-- > 0;) {
    const JointDef& def = model.joints[j].def;
    Merge(subtree[def.child_link], &subtree[def.parent_link]);
  }
  const auto joint_motion = [&](std::size_t j) {
    return UnitMotion{k.joint_axis_world[j], k.joint_anchor_world[j],
                      model.joints[j].def.type != JointType::kPrismatic};
  };
  // A floating base's six dofs move every link: (v_com, omega) of link 0.
  std::array<UnitMotion, 6> base;
  for (int axis = 0; axis < 3; ++axis) {
    base[axis] = UnitMotion{Vec3::Unit(axis), Vec3::Zero(), false};
    base[3 + axis] = UnitMotion{Vec3::Unit(axis), k.com_world[0], true};
  }
  for (int a = 0; a < model.base_dofs; ++a) {
    for (int b = a; b < model.base_dofs; ++b) {
      AddSymmetric(a, b, MotionProduct(subtree[0], base[a], UnitMomentum(subtree[0], base[b])),
                   false, mass);
    }
  }
  // Joint k's motion moves its child's subtree, which every ancestor joint
  // and the base move too: their entries are products over that subtree.
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    double factor = 1.0;
    const int dof = model.base_dofs + DrivingDof(model, static_cast<int>(j), &factor);
    const UnitMotion motion = joint_motion(j);
    const Composite& moved = subtree[model.joints[j].def.child_link];
    const Momentum momentum = UnitMomentum(moved, motion);
    AddSymmetric(dof, dof, factor * factor * MotionProduct(moved, motion, momentum), false, mass);
    for (int b = 0; b < model.base_dofs; ++b) {
      AddSymmetric(b, dof, factor * MotionProduct(moved, base[b], momentum), false, mass);
    }
    for (int up = model.links[model.joints[j].def.parent_link].parent_joint; up >= 0;
         up = model.links[model.joints[up].def.parent_link].parent_joint) {
      double up_factor = 1.0;
      const int up_dof = model.base_dofs + DrivingDof(model, up, &up_factor);
      AddSymmetric(up_dof, dof,
                   up_factor * factor * MotionProduct(moved, joint_motion(up), momentum),
                   /*distinct=*/true, mass);
    }
  }
}

// The velocity-product accelerations of the links (u' = 0), from the base
// out (the forward pass of Featherstone's recursive Newton-Euler algorithm,
// 2008, section 5.3, in world-frame vectors): for a turning joint about s
// through p, alpha_c = alpha_p + omega_p x s qdot, and
// a_c = a_p + alpha_p x (p - c_p) + omega_p x (omega_p x (p - c_p))
//       + alpha_c x (c_c - p) + omega_c x (omega_c x (c_c - p));
// for a sliding joint with d = c_c - c_p, alpha_c = alpha_p and
// a_c = a_p + alpha_p x d + omega_p x (omega_p x d) + 2 omega_p x s qdot.
void ComputeDynamics(const ArticulationModel& model, const ArticulationState& state,
                     const ArticulationKinematics& k, const Vec3& gravity,
                     const Eigen::VectorXd& joint_efforts, JointSpaceDynamics* dynamics) {
  const std::size_t link_count = model.links.size();
  const int n = model.DofCount();
  std::vector<Vec3> a(link_count, Vec3::Zero());
  std::vector<Vec3> alpha(link_count, Vec3::Zero());
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const JointDef& def = model.joints[j].def;
    const int p = def.parent_link;
    const int c = def.child_link;
    const Vec3& w_p = k.angular_velocity[p];
    const Vec3& w_c = k.angular_velocity[c];
    const Vec3 s_qdot = k.joint_axis_world[j] * k.joint_velocity[j];
    if (def.type == JointType::kPrismatic) {
      const Vec3 d = k.com_world[c] - k.com_world[p];
      alpha[c] = alpha[p];
      a[c] = a[p] + alpha[p].cross(d) + w_p.cross(w_p.cross(d)) + 2.0 * w_p.cross(s_qdot);
    } else {
      const Vec3 to_anchor = k.joint_anchor_world[j] - k.com_world[p];
      const Vec3 from_anchor = k.com_world[c] - k.joint_anchor_world[j];
      alpha[c] = alpha[p] + w_p.cross(s_qdot);
      a[c] = a[p] + alpha[p].cross(to_anchor) + w_p.cross(w_p.cross(to_anchor)) +
             alpha[c].cross(from_anchor) + w_c.cross(w_c.cross(from_anchor));
    }
  }
  JointSpaceInertia(model, k, &dynamics->mass);
  dynamics->force.setZero(n);
  Eigen::Matrix<double, 6, 1> wrench;
  for (std::size_t i = 0; i < link_count; ++i) {
    const ArticulationLink& link = model.links[i];
    const Mat3& inertia = k.inertia_world[i];
    const Vec3& w = k.angular_velocity[i];
    wrench.head<3>() = link.mass * (gravity - a[i]) + link.force;
    wrench.tail<3>() = link.torque - inertia * alpha[i] - w.cross(inertia * w);
    dynamics->force.noalias() += k.jacobian[i].transpose() * wrench;
  }
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const ArticulationJoint& joint = model.joints[j];
    if (joint.dof < 0) continue;
    dynamics->force[model.base_dofs + joint.dof] +=
        joint_efforts[joint.dof] - joint.def.damping * state.u[model.base_dofs + joint.dof];
  }
}

ArticulationState Advance(const ArticulationModel& model, const ArticulationState& state,
                          const Eigen::VectorXd& u, double h) {
  ArticulationState next = state;
  AdvanceInto(model, state, u, h, &next);
  next.u = u;
  return next;
}

void AdvanceInto(const ArticulationModel& model, const ArticulationState& state,
                 const Eigen::VectorXd& u, double h, ArticulationState* out) {
  out->base_com = state.base_com;
  out->base_rotation = state.base_rotation;
  if (model.base_dofs == 6) {
    out->base_com += h * u.head<3>();
    const Vec3 turn = h * u.segment<3>(3);
    const double angle = turn.norm();
    if (angle > 0.0) {
      out->base_rotation =
          (Quat(Eigen::AngleAxisd(angle, turn / angle)) * state.base_rotation).normalized();
    }
  }
  out->q = state.q + h * u.tail(model.joint_dofs);
}

}  // namespace rigid_body_sim::physics
