// The pivoting LCP solver against the three contact conditions, and PGS
// against the pivoting solver, on random contact problems.
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "physics/solver/lcp.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {
namespace {

struct RandomContactProblem {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
};

// A = J M^-1 J^T for `contacts` random contacts between random pairs of
// `bodies` random bodies (the a_ij of the resting-contact conditions,
// Baraff 1997, "Rigid Body Simulation II", eq. (9-8) and appendix D, are
// exactly the entries of this matrix), b random with both signs.
RandomContactProblem MakeProblem(std::mt19937* rng, int bodies, int contacts) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> mass_dist(0.5, 5.0);
  std::uniform_int_distribution<int> body_dist(0, bodies - 1);
  const int dofs = 6 * bodies;
  Eigen::VectorXd inverse_mass_diagonal(dofs);
  for (int k = 0; k < bodies; ++k) {
    const double mass = mass_dist(*rng);
    inverse_mass_diagonal.segment<3>(6 * k).setConstant(1.0 / mass);
    for (int j = 0; j < 3; ++j)
      inverse_mass_diagonal[6 * k + 3 + j] = 1.0 / (0.1 * mass_dist(*rng));
  }
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(contacts, dofs);
  for (int i = 0; i < contacts; ++i) {
    const int body_a = body_dist(*rng);
    int body_b = body_dist(*rng);
    const Vec3 normal = Vec3(unit(*rng), unit(*rng), unit(*rng)).normalized();
    const Vec3 r_a(unit(*rng), unit(*rng), unit(*rng));
    jacobian.block<1, 3>(i, 6 * body_a) = normal.transpose();
    jacobian.block<1, 3>(i, 6 * body_a + 3) = r_a.cross(normal).transpose();
    // Half the contacts are against the static world.
    if (body_b != body_a && (i % 2 == 0)) {
      const Vec3 r_b(unit(*rng), unit(*rng), unit(*rng));
      jacobian.block<1, 3>(i, 6 * body_b) -= normal.transpose();
      jacobian.block<1, 3>(i, 6 * body_b + 3) -= r_b.cross(normal).transpose();
    }
  }
  RandomContactProblem problem;
  problem.a = jacobian * inverse_mass_diagonal.asDiagonal() * jacobian.transpose();
  problem.b = Eigen::VectorXd(contacts);
  for (int i = 0; i < contacts; ++i) problem.b[i] = 2.0 * unit(*rng);
  return problem;
}

TEST(LcpTest, PivotingSatisfiesTheThreeConditionsAndPgsAgrees) {
  std::mt19937 rng(20261122);
  std::uniform_int_distribution<int> bodies_dist(1, 3);
  int solved = 0;
  double worst_violation = 0.0;
  double worst_pgs_difference = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const int bodies = bodies_dist(rng);
    // Up to 6 contacts per body keeps A positive definite, so f is unique and
    // the two solvers must agree.
    std::uniform_int_distribution<int> contacts_dist(1, std::min(8, 6 * bodies - 1));
    const RandomContactProblem problem = MakeProblem(&rng, bodies, contacts_dist(rng));
    const Result<LcpSolution> exact = SolveLcpLemke(problem.a, problem.b);
    ASSERT_TRUE(exact.ok()) << "trial " << trial << ": " << exact.message();
    const LcpSolution& solution = exact.value();
    // Repulsive, non-penetration, workless.
    EXPECT_GE(solution.f.minCoeff(), -1e-9) << "trial " << trial;
    EXPECT_GE(solution.w.minCoeff(), -1e-9) << "trial " << trial;
    EXPECT_LE(solution.f.cwiseProduct(solution.w).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    worst_violation = std::max(worst_violation, LcpViolation(problem.a, problem.b, solution.f));

    Eigen::VectorXd f_pgs = Eigen::VectorXd::Zero(problem.b.size());
    PgsSettings settings;
    settings.max_iterations = 20000;
    settings.tolerance = 1e-14;
    SolveLcpPgs(problem.a, problem.b, settings, &f_pgs);
    const double difference = (f_pgs - solution.f).cwiseAbs().maxCoeff();
    worst_pgs_difference = std::max(worst_pgs_difference, difference);
    EXPECT_LE(difference, 1e-4) << "trial " << trial;
    ++solved;
  }
  EXPECT_EQ(solved, 200);
  RecordProperty("worst_violation", std::to_string(worst_violation));
  RecordProperty("worst_pgs_difference", std::to_string(worst_pgs_difference));
}

// One body on the ground at two contacts under gravity: a 1-D problem per
// contact whose answer is known: f = max(0, -b / a).
TEST(LcpTest, DiagonalProblemHasClosedForm) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3, 3);
  a.diagonal() << 2.0, 0.5, 4.0;
  Eigen::VectorXd b(3);
  b << -4.0, 1.0, -2.0;
  const LcpSolution solution = SolveLcpLemke(a, b).value();
  EXPECT_NEAR(solution.f[0], 2.0, 1e-15);
  EXPECT_NEAR(solution.f[1], 0.0, 1e-15);
  EXPECT_NEAR(solution.f[2], 0.5, 1e-15);
  EXPECT_NEAR(solution.w[1], 1.0, 1e-15);
}

TEST(LcpTest, InfeasibleProblemIsReported) {
  // w = -f - 1 can never be >= 0 with f >= 0.
  Eigen::MatrixXd a(1, 1);
  a << -1.0;
  Eigen::VectorXd b(1);
  b << -1.0;
  EXPECT_FALSE(SolveLcpLemke(a, b).ok());
}

}  // namespace
}  // namespace rigid_body_sim::physics
