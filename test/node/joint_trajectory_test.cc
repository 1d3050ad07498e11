// The trajectory interpolation: cubic Hermite segments reproduce a cubic
// polynomial exactly from its values and slopes, and the velocity is
// continuous at every point.
#include "rigid_body_sim/node/joint_trajectory.h"

#include <cmath>

#include <gtest/gtest.h>

namespace rigid_body_sim::node {
namespace {

double Cubic(double t) { return 0.3 - 0.5 * t + 0.8 * t * t - 0.2 * t * t * t; }
double CubicSlope(double t) { return -0.5 + 1.6 * t - 0.6 * t * t; }

TEST(JointTrajectoryTest, HermiteSegmentsReproduceACubic) {
  const TrajectoryPoint start{0.0, {Cubic(0.0)}, {CubicSlope(0.0)}};
  std::vector<TrajectoryPoint> points;
  for (const double t : {0.4, 1.0, 1.7}) points.push_back({t, {Cubic(t)}, {CubicSlope(t)}});
  const auto trajectory = JointTrajectory::Make(start, points);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message();
  for (double t = 0.0; t <= 1.7; t += 0.01) {
    const TrajectorySample sample = trajectory->Sample(t);
    EXPECT_NEAR(sample.positions[0], Cubic(t), 1e-12) << t;
    EXPECT_NEAR(sample.velocities[0], CubicSlope(t), 1e-12) << t;
  }
  const TrajectorySample after = trajectory->Sample(2.5);
  EXPECT_DOUBLE_EQ(after.positions[0], Cubic(1.7));
  EXPECT_EQ(after.velocities[0], 0.0);
}

// Velocities left out are estimated from the neighbours; the commanded
// velocity has no jump at a point.
TEST(JointTrajectoryTest, EstimatedVelocitiesAreContinuousAtPoints) {
  const TrajectoryPoint start{0.0, {0.0, 1.0}, {0.0, 0.0}};
  const auto trajectory = JointTrajectory::Make(
      start, {{0.5, {0.3, 0.8}, {}}, {1.0, {0.6, 0.2}, {}}, {2.0, {0.2, 0.0}, {}}});
  ASSERT_TRUE(trajectory.ok()) << trajectory.message();
  for (const double knot : {0.5, 1.0}) {
    const TrajectorySample before = trajectory->Sample(knot - 1e-9);
    const TrajectorySample after = trajectory->Sample(knot + 1e-9);
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(before.velocities[j], after.velocities[j], 1e-6);
      EXPECT_NEAR(before.positions[j], after.positions[j], 1e-8);
    }
  }
  // At 0.5 s the first joint's slope is the mean of 0.6 and 0.6 rad/s.
  EXPECT_NEAR(trajectory->Sample(0.5).velocities[0], 0.6, 1e-12);
}

TEST(JointTrajectoryTest, RefusesBadPointsByIndex) {
  const TrajectoryPoint start{0.0, {0.0}, {0.0}};
  EXPECT_EQ(JointTrajectory::Make(start, {}).message(), "the trajectory has no points");
  EXPECT_NE(JointTrajectory::Make(start, {{1.0, {0.0}, {}}, {0.5, {0.0}, {}}})
                .message()
                .find("point 1 time_from_start 0.5"),
            std::string::npos);
  EXPECT_NE(JointTrajectory::Make(start, {{1.0, {0.0, 1.0}, {}}}).message().find("point 0 needs 1"),
            std::string::npos);
  EXPECT_FALSE(JointTrajectory::Make(start, {{1.0, {NAN}, {}}}).ok());
}

}  // namespace
}  // namespace rigid_body_sim::node
