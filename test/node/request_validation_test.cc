// The joint values of requests against the limits the README documents:
// each refusal names the joint, the field, the value and the range.
#include "rigid_body_sim/node/request_validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <string>

namespace rigid_body_sim::node {
namespace {

void ExpectRefused(const physics::Status& status, std::initializer_list<const char*> words) {
  ASSERT_FALSE(status.ok());
  for (const char* word : words) {
    EXPECT_NE(status.message().find(word), std::string::npos)
        << "'" << word << "' not in: " << status.message();
  }
}

JointValues Values(bool prismatic, double position, double velocity, double effort) {
  JointValues values;
  values.field = "joint 'elbow'";
  values.prismatic = prismatic;
  values.position = position;
  values.velocity = velocity;
  values.effort = effort;
  return values;
}

TEST(RequestValidationTest, JointValuesWithinTheirLimitsPass) {
  const RequestLimits limits;
  EXPECT_TRUE(
      ValidateJointValues(
          Values(false, -kMaxJointPosition, limits.max_angular_speed, -limits.max_torque), limits)
          .ok());
  EXPECT_TRUE(
      ValidateJointValues(
          Values(true, kMaxJointPosition, -limits.max_linear_speed, limits.max_force), limits)
          .ok());
}

TEST(RequestValidationTest, JointValuesBeyondTheirLimitsAreNamed) {
  RequestLimits limits;
  limits.max_angular_speed = 100.0;
  limits.max_linear_speed = 5.0;
  limits.max_torque = 50.0;
  limits.max_force = 20.0;
  ExpectRefused(ValidateJointValues(Values(false, 1e300, 0, 0), limits),
                {"joint 'elbow' position", "1e+300 rad", "[-10000, 10000] rad"});
  ExpectRefused(ValidateJointValues(Values(false, 0, -101, 0), limits),
                {"joint 'elbow' velocity", "-101 rad/s", "[-100, 100] rad/s"});
  ExpectRefused(ValidateJointValues(Values(true, 0, 6, 0), limits),
                {"joint 'elbow' velocity", "6 m/s", "[-5, 5] m/s"});
  ExpectRefused(ValidateJointValues(Values(false, 0, 0, 51), limits),
                {"joint 'elbow' effort", "51 N m", "[-50, 50] N m"});
  ExpectRefused(ValidateJointValues(Values(true, 0, 0, -21), limits),
                {"joint 'elbow' effort", "-21 N", "[-20, 20] N"});
  ExpectRefused(ValidateJointValues(Values(true, std::nan(""), 0, 0), limits),
                {"joint 'elbow' position", "nan"});
}

TEST(RequestValidationTest, SpawnJointPositionsShareOneBound) {
  ModelSpec spec;
  spec.name = "arm";
  spec.friction = -1.0;
  spec.restitution = -1.0;
  spec.joint_positions = {{"wrist", 1e300}};
  ExpectRefused(ValidateModelSpec(spec, RequestLimits()),
                {"joint_positions of 'wrist'", "1e+300", "[-10000, 10000]"});
  spec.joint_positions = {{"wrist", -kMaxJointPosition}};
  EXPECT_TRUE(ValidateModelSpec(spec, RequestLimits()).ok());
}

}  // namespace
}  // namespace rigid_body_sim::node
