// The composite-rigid-body joint-space inertia against the reference sum
// over the links' Jacobians, on random trees: turning and sliding joints,
// mimic joints, fixed and floating bases, far from the origin and near it.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "physics/articulation/articulation_dynamics.h"

namespace rigid_body_sim::physics {
namespace {

// Coordinates drawn one statement at a time: the order in which a call's
// arguments are evaluated is unspecified.
Vec3 RandomVector(std::mt19937* random, double scale) {
  std::uniform_real_distribution<double> coordinate(-scale, scale);
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = coordinate(*random);
  return v;
}

Quat RandomRotation(std::mt19937* random) {
  std::normal_distribution<double> normal;
  Eigen::Vector4d q;
  for (int k = 0; k < 4; ++k) q[k] = normal(*random);
  return Quat(q.normalized());
}

// A tree of `links` links, each joint's parent drawn from the links before
// its child; with `mimics`, every fourth joint past the first mimics an
// earlier joint that mimics none.
ArticulationModel RandomTree(int links, bool floating, std::mt19937* random, bool mimics = true) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ArticulationModel model;
  model.fixed_base = !floating;
  model.base_dofs = floating ? 6 : 0;
  for (int i = 0; i < links; ++i) {
    ArticulationLink link;
    link.mass = 0.1 + 5.0 * unit(*random);
    link.com_link = RandomVector(random, 0.3);
    const Vec3 moments = Vec3(0.01, 0.01, 0.01) + RandomVector(random, 0.005).cwiseAbs();
    const Mat3 rotation = RandomRotation(random).toRotationMatrix();
    link.inertia_link = rotation * moments.asDiagonal() * rotation.transpose();
    model.links.push_back(link);
  }
  std::vector<int> leaders;
  for (int child = 1; child < links; ++child) {
    ArticulationJoint joint;
    joint.def.parent_link = std::uniform_int_distribution<int>(0, child - 1)(*random);
    joint.def.child_link = child;
    joint.def.type = unit(*random) < 0.25 ? JointType::kPrismatic : JointType::kRevolute;
    joint.def.parent_from_joint = Pose{RandomVector(random, 0.5), RandomRotation(random)};
    joint.def.axis = RandomVector(random, 1.0).normalized();
    const int index = static_cast<int>(model.joints.size());
    joint.def.damping = unit(*random) < 0.5 ? 0.0 : 2.0 * unit(*random);
    if (mimics && index > 0 && index % 4 == 0) {
      joint.def.mimic_joint =
          leaders[std::uniform_int_distribution<std::size_t>(0, leaders.size() - 1)(*random)];
      joint.def.mimic_multiplier = -2.0 + 4.0 * unit(*random);
    } else {
      joint.dof = model.joint_dofs++;
      leaders.push_back(index);
    }
    model.links[child].parent_joint = index;
    model.joints.push_back(joint);
  }
  return model;
}

ArticulationState RandomState(const ArticulationModel& model, const Vec3& where,
                              std::mt19937* random) {
  ArticulationState state;
  state.base_com = where;
  state.base_rotation = RandomRotation(random);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  state.q.resize(model.joint_dofs);
  for (Eigen::Index k = 0; k < state.q.size(); ++k) state.q[k] = coordinate(*random);
  state.u.resize(model.DofCount());
  for (Eigen::Index k = 0; k < state.u.size(); ++k) state.u[k] = coordinate(*random);
  return state;
}

// Largest |difference| of the two, over the largest |entry|.
double RelativeDifference(const Eigen::MatrixXd& fast, const Eigen::MatrixXd& reference) {
  return (fast - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff();
}

TEST(JointSpaceInertiaTest, CompositeBodiesMatchTheSumOverJacobiansOnRandomTrees) {
  std::mt19937 random(20261127);
  int compared = 0;
  for (const bool floating : {false, true}) {
    for (const int links : {2, 3, 7, 16, 31}) {
      for (const Vec3& where : {Vec3(0.0, 0.0, 1.0), Vec3(150.0, -80.0, 20.0)}) {
        const ArticulationModel model = RandomTree(links, floating, &random);
        const ArticulationState state = RandomState(model, where, &random);
        ArticulationKinematics kinematics;
        ComputeKinematics(model, state, &kinematics, KinematicsParts::kWithJacobians);
        Eigen::MatrixXd fast;
        Eigen::MatrixXd reference;
        JointSpaceInertia(model, kinematics, &fast);
        JointSpaceInertiaByJacobians(model, kinematics, &reference);
        ASSERT_EQ(fast.rows(), model.DofCount());
        ASSERT_EQ(fast.cols(), model.DofCount());
        // Both are sums of the same terms in another order: rounding apart.
        EXPECT_LT(RelativeDifference(fast, reference), 1e-12)
            << links << " links, floating " << floating << ", at " << where.transpose();
        EXPECT_LT((fast - fast.transpose()).cwiseAbs().maxCoeff(), 1e-15 * fast.norm());
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 20);
}

// The articulated-body algorithm's u' = (M + h B)^-1 Q against the
// composite-rigid-body M and a dense Cholesky solve, on random trees without
// mimics: turning and sliding joints with damping, moving states, efforts,
// wrenches on the links, fixed and floating bases, near the origin and far,
// damping explicit (h = 0) and implicit over a step. The velocities of the
// Jacobian-free kinematics are the Jacobians' J u.
TEST(JointSpaceInertiaTest, ArticulatedBodyAlgorithmMatchesTheCompositeRigidBodySolve) {
  std::mt19937 random(20261128);
  std::uniform_real_distribution<double> effort(-3.0, 3.0);
  int compared = 0;
  for (const bool floating : {false, true}) {
    for (const int links : {2, 3, 7, 16, 31}) {
      for (const Vec3& where : {Vec3(0.0, 0.0, 1.0), Vec3(150.0, -80.0, 20.0)}) {
        for (const double damping_step : {0.0, 1.0 / 240.0}) {
          ArticulationModel model = RandomTree(links, floating, &random, /*mimics=*/false);
          for (ArticulationLink& link : model.links) {
            link.force = RandomVector(&random, 2.0);
            link.torque = RandomVector(&random, 0.5);
          }
          const ArticulationState state = RandomState(model, where, &random);
          Eigen::VectorXd efforts(model.joint_dofs);
          for (Eigen::Index k = 0; k < efforts.size(); ++k) efforts[k] = effort(random);
          const Vec3 gravity(0.3, -0.2, -9.81);
          ArticulationKinematics kinematics;
          ComputeKinematics(model, state, &kinematics, KinematicsParts::kPosesAndVelocities);
          ASSERT_TRUE(ArticulatedBodyApplies(model));
          ArticulatedBodyScratch scratch;
          Eigen::VectorXd fast;
          ArticulatedBodyForwardDynamics({model, state, kinematics, gravity, efforts, damping_step},
                                         &scratch, &fast);
          ArticulationKinematics with_jacobians;
          Eigen::VectorXd reference;
          CompositeRigidBodyForwardDynamics(
              {model, state, kinematics, gravity, efforts, damping_step}, &with_jacobians,
              &reference);
          ASSERT_EQ(fast.size(), model.DofCount());
          EXPECT_LT((fast - reference).cwiseAbs().maxCoeff(),
                    1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()))
              << links << " links, floating " << floating << ", at " << where.transpose() << ", h "
              << damping_step;
          for (std::size_t i = 0; i < model.links.size(); ++i) {
            const double scale = 1.0 + state.u.cwiseAbs().maxCoeff() * 10.0;
            EXPECT_LT(
                (kinematics.linear_velocity[i] - with_jacobians.jacobian[i].topRows<3>() * state.u)
                    .norm(),
                1e-12 * scale);
            EXPECT_LT((kinematics.angular_velocity[i] -
                       with_jacobians.jacobian[i].bottomRows<3>() * state.u)
                          .norm(),
                      1e-12 * scale);
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 40);
}

// An articulated-body evaluation of `model` at `state` with damping step
// h, its response to M + h B captured, and the kinematics it read.
ArticulatedResponse CaptureResponse(const ArticulationModel& model, const ArticulationState& state,
                                    double h, ArticulationKinematics* kinematics) {
  ComputeKinematics(model, state, kinematics, KinematicsParts::kPosesAndVelocities);
  ArticulatedBodyScratch scratch;
  Eigen::VectorXd acceleration;
  ArticulatedBodyForwardDynamics(
      {model, state, *kinematics, Vec3(0, 0, -9.81), Eigen::VectorXd::Zero(model.joint_dofs), h},
      &scratch, &acceleration);
  ArticulatedResponse response;
  response.Capture(model, scratch);
  return response;
}

// B: the joints' damping on the diagonal of their columns.
Eigen::MatrixXd DampingMatrix(const ArticulationModel& model) {
  Eigen::MatrixXd damping = Eigen::MatrixXd::Zero(model.DofCount(), model.DofCount());
  for (const ArticulationJoint& joint : model.joints) {
    damping(model.base_dofs + joint.dof, model.base_dofs + joint.dof) = joint.def.damping;
  }
  return damping;
}

// The row solve's M^-1 J^T of a large model from the articulated-body
// passes (ArticulatedResponse) against the dense factor of M + h B, for
// generalized forces of every kind: a joint's unit, a point force's row on
// a random link, and a random vector; fixed and floating bases, h = 0 and
// 1/240 s with damped joints.
TEST(JointSpaceInertiaTest, ArticulatedResponseMatchesTheDenseFactor) {
  std::mt19937 random(20261203);
  int compared = 0;
  for (const bool floating : {false, true}) {
    for (const int links : {2, 5, 16, 40}) {
      for (const double damping_step : {0.0, 1.0 / 240.0}) {
        const ArticulationModel model = RandomTree(links, floating, &random, /*mimics=*/false);
        const ArticulationState state = RandomState(model, Vec3(3.0, -2.0, 1.0), &random);
        ArticulationKinematics kinematics;
        ArticulatedResponse response = CaptureResponse(model, state, damping_step, &kinematics);
        Eigen::MatrixXd mass;
        JointSpaceInertia(model, kinematics, &mass);
        const Eigen::LLT<Eigen::MatrixXd> factor(mass + damping_step * DampingMatrix(model));
        std::vector<Eigen::VectorXd> forces;
        forces.push_back(Eigen::VectorXd::Unit(model.DofCount(), model.DofCount() - 1));
        const int link = std::uniform_int_distribution<int>(1, links - 1)(random);
        const Vec3 point = kinematics.com_world[link] + RandomVector(&random, 0.2);
        std::array<Eigen::VectorXd, 3> rows;
        PointVelocityRows(model, kinematics,
                          {link, point, {RandomVector(&random, 1.0), Vec3::Zero(), Vec3::Zero()}},
                          &rows);
        forces.push_back(rows[0]);
        forces.push_back(Eigen::VectorXd::Random(model.DofCount()));
        std::array<Eigen::VectorXd, 3> together;
        response.ApplyThree({&forces[0], &forces[1], &forces[2]}, model.DofCount(),
                            {&together[0], &together[1], &together[2]});
        for (int f = 0; f < 3; ++f) {
          const Eigen::VectorXd& force = forces[f];
          const Eigen::VectorXd reference = factor.solve(force);
          // Alone over the whole u, alone from its last nonzero entry (the
          // joints past it skipped), and with the other two.
          Eigen::Index extent = force.size();
          while (extent > 0 && force[extent - 1] == 0.0) --extent;
          std::array<Eigen::VectorXd, 3> fast;
          response.Apply(force, force.size(), &fast[0]);
          response.Apply(force, extent, &fast[1]);
          fast[2] = together[f];
          for (const Eigen::VectorXd& candidate : fast) {
            ASSERT_EQ(candidate.size(), reference.size());
            EXPECT_LT((candidate - reference).cwiseAbs().maxCoeff(),
                      1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()))
                << links << " links, floating " << floating << ", h " << damping_step << ", force "
                << f;
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 144);
}

// The damping's fastest decay rate by the power method against the largest
// generalized eigenvalue of B x = lambda M x from a dense solver: never
// above it (its Rayleigh quotients rise from below), and within 1e-6 of it
// after 30 calls of 4 iterations each, on random trees with half their
// joints damped, fixed and floating, from the response to M and to M + h B.
TEST(JointSpaceInertiaTest, FastestDampingRateRisesToTheGeneralizedEigenvalue) {
  std::mt19937 random(20261204);
  int compared = 0;
  for (const bool floating : {false, true}) {
    for (const int links : {3, 12, 40}) {
      for (const double h : {0.0, 1.0 / 240.0}) {
        ArticulationModel model = RandomTree(links, floating, &random, /*mimics=*/false);
        for (std::size_t j = 0; j < model.joints.size(); ++j) {
          model.joints[j].def.damping =
              j % 2 == 0 ? std::uniform_real_distribution<double>(0.1, 2.0)(random) : 0.0;
        }
        const ArticulationState state = RandomState(model, Vec3(1.0, 2.0, 0.5), &random);
        ArticulationKinematics kinematics;
        ArticulatedResponse response = CaptureResponse(model, state, h, &kinematics);
        Eigen::MatrixXd mass;
        JointSpaceInertia(model, kinematics, &mass);
        const double exact =
            Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(DampingMatrix(model), mass)
                .eigenvalues()
                .maxCoeff();
        ASSERT_GT(exact, 0.0);
        DampingModeScratch modes;
        double rate = 0.0;
        for (int call = 0; call < 30; ++call) {
          rate = FastestDampingRate(model, h, &response, &modes);
          EXPECT_LE(rate, exact * (1.0 + 1e-9)) << links << " links, call " << call;
        }
        EXPECT_NEAR(rate / exact, 1.0, 1e-6) << links << " links, floating " << floating;
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 12);
}

// A contact point's three rows from the joints on the link's path to the
// base against the link's dense Jacobian, J_v^T d + J_w^T ((p - c) x d), on
// random trees with mimics (which share their leader's column), fixed and
// floating, and their dots with u against d . (v_c + omega x (p - c)) from
// the kinematics.
TEST(JointSpaceInertiaTest, PointVelocityRowsMatchTheLinkJacobian) {
  std::mt19937 random(20261202);
  int compared = 0;
  for (const bool floating : {false, true}) {
    for (const int links : {2, 7, 31}) {
      for (const Vec3& where : {Vec3(0.0, 0.0, 1.0), Vec3(150.0, -80.0, 20.0)}) {
        const ArticulationModel model = RandomTree(links, floating, &random);
        const ArticulationState state = RandomState(model, where, &random);
        ArticulationKinematics kinematics;
        ComputeKinematics(model, state, &kinematics, KinematicsParts::kWithJacobians);
        for (int link = 0; link < links; ++link) {
          const Vec3 point = kinematics.com_world[link] + RandomVector(&random, 0.4);
          std::array<Vec3, 3> directions;
          for (Vec3& direction : directions) direction = RandomVector(&random, 1.0).normalized();
          std::array<Eigen::VectorXd, 3> rows;
          PointVelocityRows(model, kinematics, {link, point, directions}, &rows);
          const JacobianRows& jacobian = kinematics.jacobian[link];
          for (int r = 0; r < 3; ++r) {
            const Vec3& direction = directions[r];
            const Eigen::VectorXd reference =
                jacobian.topRows<3>().transpose() * direction +
                jacobian.bottomRows<3>().transpose() *
                    (point - kinematics.com_world[link]).cross(direction);
            const Eigen::VectorXd& row = rows[r];
            ASSERT_EQ(row.size(), model.DofCount());
            const double scale = std::max(reference.cwiseAbs().maxCoeff(), 1.0);
            EXPECT_LT((row - reference).cwiseAbs().maxCoeff(), 1e-12 * scale)
                << links << " links, floating " << floating << ", link " << link;
            const Vec3 velocity =
                kinematics.linear_velocity[link] +
                kinematics.angular_velocity[link].cross(point - kinematics.com_world[link]);
            EXPECT_NEAR(row.dot(state.u), direction.dot(velocity),
                        1e-12 * scale * std::max(state.u.norm(), 1.0));
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 3 * 2 * 2 * (2 + 7 + 31));
}

// A single link turning about an axis through its hinge: M = I_axis + m d^2,
// the parallel-axis theorem, with d the centre's distance from the axis.
TEST(JointSpaceInertiaTest, OneHingeGivesTheParallelAxisTheorem) {
  ArticulationModel model;
  ArticulationLink base;
  base.mass = 1.0;
  ArticulationLink bob;
  bob.mass = 2.0;
  bob.com_link = Vec3(0.0, 0.0, -0.5);
  bob.inertia_link = Vec3(0.03, 0.04, 0.05).asDiagonal();
  bob.parent_joint = 0;
  model.links = {base, bob};
  ArticulationJoint hinge;
  hinge.def.parent_link = 0;
  hinge.def.child_link = 1;
  hinge.def.axis = Vec3::UnitY();
  hinge.dof = 0;
  model.joints = {hinge};
  model.joint_dofs = 1;
  ArticulationState state;
  state.q = Eigen::VectorXd::Constant(1, 0.3);
  state.u = Eigen::VectorXd::Zero(1);
  ArticulationKinematics kinematics;
  ComputeKinematics(model, state, &kinematics, KinematicsParts::kWithJacobians);
  Eigen::MatrixXd mass;
  JointSpaceInertia(model, kinematics, &mass);
  EXPECT_NEAR(mass(0, 0), 0.04 + 2.0 * 0.5 * 0.5, 1e-15);
}

}  // namespace
}  // namespace rigid_body_sim::physics
