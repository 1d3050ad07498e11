// Validation of the node's parameters; no ROS master needed.
#include "rigid_body_sim/node/options.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rigid_body_sim::node {
namespace {

using physics::Vec3;

TEST(OptionsTest, DefaultsAreValid) { EXPECT_TRUE(ValidateNodeOptions(NodeOptions()).ok()); }

TEST(OptionsTest, BadValuesAreNamed) {
  NodeOptions options;
  options.world.time_step = -0.01;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~time_step -0.01 s is outside the allowed range [1e-05, 0.1] s");
  options = NodeOptions();
  options.real_time_factor = -1.0;
  EXPECT_NE(ValidateNodeOptions(options).message().find("~real_time_factor"), std::string::npos);
  options = NodeOptions();
  options.ground_restitution = 1.5;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~ground_restitution 1.5 is outside the allowed range [0, 1]");
  options = NodeOptions();
  options.world_frame = "/world";
  EXPECT_NE(ValidateNodeOptions(options).message().find("leading slash"), std::string::npos);
  options = NodeOptions();
  options.servo.stiffness = 0.0;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~joint_stiffness 0 N m/rad is outside the allowed range (0, 1e+12] N m/rad");
  options = NodeOptions();
  options.servo.damping = -1.0;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~joint_damping -1 N m s/rad is outside the allowed range [0, 1e+12] N m s/rad");
  options = NodeOptions();
  options.world.threads = -1;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~threads -1 is outside the allowed range [0, 256]");
  options.world.threads = 257;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~threads 257 is outside the allowed range [0, 256]");
  options = NodeOptions();
  options.world.max_turn_per_step = 4.0;
  EXPECT_NE(
      ValidateNodeOptions(options).message().find("max_turn_per_step 4 rad must be in (0, pi]"),
      std::string::npos)
      << ValidateNodeOptions(options).message();
}

// ~solver/method names one of the two solvers; anything else, and a soft
// step setting out of its range, is refused with its name.
TEST(OptionsTest, SolverMethodIsExactOrSoftStep) {
  NodeOptions options;
  EXPECT_EQ(options.solver_method, "exact");
  options.solver_method = "soft_step";
  EXPECT_TRUE(ValidateNodeOptions(options).ok());
  physics::MotionSolverKind kind = physics::MotionSolverKind::kExact;
  ASSERT_TRUE(SolverMethodFromName(options.solver_method, &kind));
  EXPECT_EQ(kind, physics::MotionSolverKind::kSoftStep);
  EXPECT_EQ(SolverMethodName(kind), "soft_step");
  options.solver_method = "pgs";
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~solver/method 'pgs' is not a solver: 'exact' or 'soft_step'");
  options = NodeOptions();
  options.world.soft_step.substeps = 65;
  EXPECT_NE(ValidateNodeOptions(options).message().find("soft_step.substeps 65 must be in [1, 64]"),
            std::string::npos)
      << ValidateNodeOptions(options).message();
  options = NodeOptions();
  options.world.soft_step.load_tracking = 2.0;
  EXPECT_NE(ValidateNodeOptions(options).message().find("load_tracking 2 must be in [0, 1]"),
            std::string::npos);
}

// ~threads defaults to one thread; 0 (every core) and 2 are valid.
TEST(OptionsTest, ThreadsDefaultToOne) {
  NodeOptions options;
  EXPECT_EQ(options.world.threads, 1);
  options.world.threads = 0;
  EXPECT_TRUE(ValidateNodeOptions(options).ok());
  options.world.threads = 2;
  EXPECT_TRUE(ValidateNodeOptions(options).ok());
}

TEST(OptionsTest, LiveRangesHoldAtStartUpAndWarnAboveAThirtiethOfASecond) {
  NodeOptions options;
  options.world.time_step = 0.5;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~time_step 0.5 s is outside the allowed range [1e-05, 0.1] s");
  options = NodeOptions();
  options.world.gravity.y() = 2000.0;
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~gravity [0, 2000, -9.81] m/s^2 (magnitude 2000.02) is outside the allowed range "
            "[0, 1000] m/s^2");
  LiveSettings live = LiveSettingsOf(NodeOptions());
  EXPECT_TRUE(ValidateLiveSettings(live, "").ok());
  EXPECT_TRUE(LiveSettingsWarnings(live, "").empty());
  live.time_step = 0.05;
  ASSERT_TRUE(ValidateLiveSettings(live, "").ok());
  ASSERT_EQ(LiveSettingsWarnings(live, "").size(), 1u);
  EXPECT_EQ(LiveSettingsWarnings(live, "")[0],
            "time_step 0.05 s is above 1/30 s: contacts and fast bodies are resolved coarsely");
  live.velocity_iterations = 0;
  EXPECT_EQ(ValidateLiveSettings(live, "").message(),
            "solver/velocity_iterations 0 is outside [1, 1000]");
  live = LiveSettingsOf(NodeOptions());
  live.sleep_angular_velocity = std::nan("");
  EXPECT_EQ(ValidateLiveSettings(live, "").message(),
            "sleep/angular_velocity nan rad/s is outside [0, 10] rad/s");
}

TEST(OptionsTest, ModelListNeedsUniqueNamesAndASource) {
  NodeOptions options;
  ModelSpec spec;
  spec.name = "box";
  spec.urdf_path = "box.urdf";
  options.models = {spec, spec};
  EXPECT_EQ(ValidateNodeOptions(options).message(), "~models: the name 'box' is used twice");
  options.models = {spec};
  options.models[0].urdf_path.clear();
  EXPECT_EQ(ValidateNodeOptions(options).message(),
            "~models: 'box' has neither urdf nor urdf_path");
}

TEST(OptionsTest, RollPitchYawIsFixedAxisXThenYThenZ) {
  // A quarter yaw takes x to y; a quarter pitch takes x to -z; applied after
  // the pitch, the yaw leaves -z alone: R = Rz Ry Rx.
  EXPECT_TRUE((QuatFromRollPitchYaw(0, 0, M_PI / 2) * Vec3::UnitX()).isApprox(Vec3::UnitY()));
  EXPECT_TRUE((QuatFromRollPitchYaw(0, M_PI / 2, 0) * Vec3::UnitX()).isApprox(-Vec3::UnitZ()));
  EXPECT_TRUE(
      (QuatFromRollPitchYaw(0, M_PI / 2, M_PI / 2) * Vec3::UnitX()).isApprox(-Vec3::UnitZ()));
  EXPECT_TRUE(
      (QuatFromRollPitchYaw(M_PI / 2, 0, M_PI / 2) * Vec3::UnitY()).isApprox(Vec3::UnitZ()));
}

}  // namespace
}  // namespace rigid_body_sim::node
