// Services, pause and step, reset, delete, markers and bad input, driven
// through the node's ROS interface. None of these need contacts: bodies sit
// high above the ground or gravity is off.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include "rigid_body_sim/node/msg_conversion.h"
#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr double kTimeout = 20.0;  // s of wall time for any single wait

class NodeServicesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(client_.WaitForServices(kTimeout));
    ASSERT_TRUE(client_.SetPaused(true));
  }
  void TearDown() override {
    for (const std::string& name : spawned_) client_.Delete(name);
    client_.SetPaused(false);
  }
  void SpawnBox(const std::string& name, const geometry_msgs::Pose& pose, double mass = 1.0) {
    const auto response = client_.SpawnUrdf(name, BoxUrdf(1.0, 1.0, 1.0, mass), pose);
    ASSERT_TRUE(response.success) << response.message;
    spawned_.push_back(name);
  }
  // Number of frames in the first ~states message published after the call.
  int FrameCount() {
    const auto states = states_.Next(kTimeout);
    EXPECT_TRUE(states.has_value());
    return states ? static_cast<int>(states->name.size()) : -1;
  }

  ros::NodeHandle node_{"/rigid_body_sim"};
  // One connection per service for the whole test: a call on a connection
  // of its own now and then fails in roscpp under load ("service call
  // failed" with the node healthy; ros/ros_comm#1976, a race in the
  // per-call connection's teardown), which made this test flaky.
  SimClient client_{/*persistent=*/true};
  Latest<rigid_body_sim::ModelStates> states_{node_, "states"};
  std::vector<std::string> spawned_;
};

TEST_F(NodeServicesTest, StepAdvancesSimTimeByExactlyStepsTimesTimeStep) {
  const double time_step = client_.GetPhysics().time_step;
  const auto before = client_.Step(0);
  ASSERT_TRUE(before.success) << before.message;
  const auto after = client_.Step(240);
  ASSERT_TRUE(after.success) << after.message;
  // 240 additions of the time step; only rounding separates them from the product.
  EXPECT_NEAR(after.sim_time - before.sim_time, 240.0 * time_step, 1e-12);
}

TEST_F(NodeServicesTest, PosesStayConstantWhilePaused) {
  SpawnBox("paused_box", MakePose(0.0, 0.0, 50.0));
  const auto first = client_.GetState("paused_box");
  ASSERT_TRUE(first.success) << first.message;
  // Three ~states messages span at least two publish periods of running time.
  for (int i = 0; i < 3; ++i) {
    const auto states = states_.Next(kTimeout);
    ASSERT_TRUE(states.has_value());
    bool found = false;
    for (std::size_t k = 0; k < states->name.size(); ++k) {
      if (states->name[k] != "paused_box/base_link") continue;
      found = true;
      EXPECT_EQ(states->pose[k].position.z, first.pose.position.z);
    }
    EXPECT_TRUE(found);
  }
  const auto later = client_.GetState("paused_box");
  EXPECT_EQ(later.pose.position.z, first.pose.position.z);
  // The same body does move when stepped (gravity is on).
  ASSERT_TRUE(client_.Step(10).success);
  EXPECT_LT(client_.GetState("paused_box").pose.position.z, first.pose.position.z);
}

TEST_F(NodeServicesTest, GetStateAgreesWithTf) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  SpawnBox("tf_box", MakePose(1.0, 2.0, 40.0, 0.9, 0.1, 0.2, 0.3));
  rigid_body_sim::SetState::Request spin;
  spin.name = "tf_box";
  spin.pose = MakePose(1.0, 2.0, 40.0, 0.9, 0.1, 0.2, 0.3);
  spin.twist.linear.x = 0.5;
  spin.twist.angular.z = 2.0;
  ASSERT_TRUE(client_.SetState(spin).success);
  ASSERT_TRUE(client_.Step(25).success);
  // While paused, tf carries a pose only when a step makes it new; steps are
  // repeated until the listener, which may still be connecting, has one.
  rigid_body_sim::GetState::Response state;
  geometry_msgs::TransformStamped transform;
  const auto tf_has_step = [&] {
    const auto stepped = client_.Step(1);
    state = client_.GetState("tf_box");
    return stepped.success && state.success &&
           WaitFor(
               [&] {
                 if (!buffer.canTransform("world", "tf_box/base_link", ros::Time(0))) return false;
                 transform = buffer.lookupTransform("world", "tf_box/base_link", ros::Time(0));
                 return std::abs(transform.header.stamp.toSec() - stepped.sim_time) < 1e-6;
               },
               1.0);
  };
  ASSERT_TRUE(WaitFor(tf_has_step, kTimeout));
  EXPECT_NEAR(transform.transform.translation.x, state.pose.position.x, 1e-9);
  EXPECT_NEAR(transform.transform.translation.y, state.pose.position.y, 1e-9);
  EXPECT_NEAR(transform.transform.translation.z, state.pose.position.z, 1e-9);
  EXPECT_NEAR(transform.transform.rotation.w, state.pose.orientation.w, 1e-9);
  EXPECT_NEAR(transform.transform.rotation.x, state.pose.orientation.x, 1e-9);
  EXPECT_NEAR(transform.transform.rotation.y, state.pose.orientation.y, 1e-9);
  EXPECT_NEAR(transform.transform.rotation.z, state.pose.orientation.z, 1e-9);
}

TEST_F(NodeServicesTest, SetStateTeleportsAndNormalisesTheQuaternion) {
  SpawnBox("teleport_box", MakePose(0.0, 0.0, 30.0));
  rigid_body_sim::SetState::Request request;
  request.name = "teleport_box/base_link";
  // A quaternion of norm 2*sqrt(2) for a quarter turn about z.
  request.pose = MakePose(3.0, 4.0, 25.0, 2.0, 0.0, 0.0, 2.0);
  request.twist.linear.x = 1.5;
  request.twist.angular.z = -0.5;
  const auto response = client_.SetState(request);
  ASSERT_TRUE(response.success) << response.message;
  const auto state = client_.GetState("teleport_box");
  ASSERT_TRUE(state.success);
  EXPECT_NEAR(state.pose.position.x, 3.0, 1e-12);
  EXPECT_NEAR(state.pose.position.y, 4.0, 1e-12);
  EXPECT_NEAR(state.pose.position.z, 25.0, 1e-12);
  EXPECT_NEAR(state.pose.orientation.w, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(state.pose.orientation.z, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(state.twist.linear.x, 1.5, 1e-12);
  EXPECT_NEAR(state.twist.angular.z, -0.5, 1e-12);
}

TEST_F(NodeServicesTest, WrenchOfTenNewtonsForOneSecondGivesTenMetresPerSecond) {
  const auto physics = client_.GetPhysics();
  rigid_body_sim::SetPhysics::Request weightless;
  weightless.time_step = physics.time_step;
  weightless.real_time_factor = physics.real_time_factor;
  ASSERT_TRUE(client_.SetPhysics(weightless).success);
  SpawnBox("pushed_box", MakePose(0.0, 5.0, 20.0), 1.0);
  rigid_body_sim::ApplyWrench::Request push;
  push.name = "pushed_box";
  push.point = MakePose(0.0, 5.0, 20.0).position;  // the centre of mass: no torque
  push.wrench.force.x = 10.0;
  push.duration = 1.0;
  const auto applied = client_.ApplyWrench(push);
  ASSERT_TRUE(applied.success) << applied.message;
  const auto steps = static_cast<std::uint32_t>(std::lround(1.0 / physics.time_step));
  ASSERT_TRUE(client_.Step(steps).success);
  // Impulse F n dt = 10 N s on 1 kg: v = 10 m/s, to rounding (no gravity,
  // no contact, the force constant over every step).
  const double expected = 10.0 * steps * physics.time_step;
  EXPECT_NEAR(client_.GetState("pushed_box").twist.linear.x, expected, 1e-9);
  // The wrench has ended: the velocity stays.
  ASSERT_TRUE(client_.Step(steps).success);
  const auto coasting = client_.GetState("pushed_box");
  EXPECT_NEAR(coasting.twist.linear.x, expected, 1e-9);
  EXPECT_NEAR(coasting.twist.angular.z, 0.0, 1e-9);
  rigid_body_sim::SetPhysics::Request restore;
  restore.gravity = physics.gravity;
  restore.time_step = physics.time_step;
  restore.real_time_factor = physics.real_time_factor;
  ASSERT_TRUE(client_.SetPhysics(restore).success);
}

TEST_F(NodeServicesTest, ResetRestoresSpawnStatesAndSimTime) {
  rigid_body_sim::Spawn::Request request;
  request.name = "reset_box";
  request.urdf = BoxUrdf(0.5, 0.5, 0.5, 2.0);
  request.pose = MakePose(1.0, -2.0, 60.0, std::cos(0.3), std::sin(0.3), 0.0, 0.0);
  request.twist.linear.y = 0.25;
  request.twist.angular.x = 1.0;
  request.friction = request.restitution = -1.0;
  ASSERT_TRUE(client_.Spawn(request).success);
  spawned_.push_back("reset_box");
  ASSERT_TRUE(client_.SetPaused(false));
  ASSERT_TRUE(
      WaitFor([&] { return client_.GetState("reset_box").pose.position.z < 59.0; }, kTimeout));
  ASSERT_TRUE(client_.SetPaused(true));
  ASSERT_TRUE(client_.Reset());
  const auto state = client_.GetState("reset_box");
  EXPECT_NEAR(state.pose.position.x, 1.0, 1e-9);
  EXPECT_NEAR(state.pose.position.y, -2.0, 1e-9);
  EXPECT_NEAR(state.pose.position.z, 60.0, 1e-9);
  EXPECT_NEAR(state.pose.orientation.w, std::cos(0.3), 1e-9);
  EXPECT_NEAR(state.pose.orientation.x, std::sin(0.3), 1e-9);
  EXPECT_NEAR(state.twist.linear.y, 0.25, 1e-9);
  EXPECT_NEAR(state.twist.angular.x, 1.0, 1e-9);
  EXPECT_EQ(client_.Step(0).sim_time, 0.0);
}

TEST_F(NodeServicesTest, DeleteRemovesTheFrameAndFreesTheName) {
  SpawnBox("doomed_box", MakePose(0.0, 0.0, 30.0));
  const auto has_frame = [&](const rigid_body_sim::ModelStates& states) {
    return std::count(states.name.begin(), states.name.end(), "doomed_box/base_link") == 1;
  };
  auto states = states_.Next(kTimeout);
  ASSERT_TRUE(states && has_frame(*states));
  const auto deleted = client_.Delete("doomed_box");
  ASSERT_TRUE(deleted.success) << deleted.message;
  states = states_.Next(kTimeout);
  ASSERT_TRUE(states.has_value());
  EXPECT_FALSE(has_frame(*states));
  EXPECT_FALSE(client_.GetState("doomed_box").success);
  const auto again = client_.SpawnUrdf("doomed_box", BoxUrdf(1, 1, 1, 1), MakePose(0, 0, 30));
  EXPECT_TRUE(again.success) << again.message;
  ASSERT_EQ(again.frames.size(), 1u);
  EXPECT_EQ(again.frames[0], "doomed_box/base_link");
  states = states_.Next(kTimeout);
  ASSERT_TRUE(states && has_frame(*states));
}

TEST_F(NodeServicesTest, BodyMarkersShowCollisionGeometryAndFollowDeletes) {
  Latest<visualization_msgs::MarkerArray> markers(node_, "body_markers");
  // A new subscriber first gets every body, the ground included.
  ASSERT_TRUE(WaitFor([&] { return markers.count() > 0; }, kTimeout));
  bool ground_seen = false;
  const visualization_msgs::MarkerArray initial = *markers.Get();
  for (const auto& marker : initial.markers) {
    ground_seen |= marker.ns == "ground" && marker.type == visualization_msgs::Marker::CUBE;
  }
  EXPECT_TRUE(ground_seen);

  std::uint64_t seen = markers.count();
  const auto box = client_.SpawnUrdf("marker_box", BoxUrdf(1.0, 2.0, 3.0, 1.0), MakePose(0, 0, 30));
  ASSERT_TRUE(box.success) << box.message;
  spawned_.push_back("marker_box");
  ASSERT_TRUE(WaitFor([&] { return markers.count() > seen; }, kTimeout));
  auto array = *markers.Get();
  ASSERT_EQ(array.markers.size(), 1u);
  const auto& hull = array.markers[0];
  EXPECT_EQ(hull.ns, "marker_box");
  EXPECT_EQ(hull.header.frame_id, "marker_box/base_link");
  EXPECT_TRUE(hull.frame_locked);
  EXPECT_EQ(hull.type, visualization_msgs::Marker::TRIANGLE_LIST);
  // Six rectangular faces, two triangles each; their area is the box's surface.
  ASSERT_EQ(hull.points.size(), 36u);
  double area = 0.0;
  for (std::size_t i = 0; i < hull.points.size(); i += 3) {
    const auto& a = hull.points[i];
    const auto& b = hull.points[i + 1];
    const auto& c = hull.points[i + 2];
    const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    const double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
    area += 0.5 * std::sqrt(std::pow(uy * vz - uz * vy, 2) + std::pow(uz * vx - ux * vz, 2) +
                            std::pow(ux * vy - uy * vx, 2));
  }
  EXPECT_NEAR(area, 2.0 * (1.0 * 2.0 + 2.0 * 3.0 + 1.0 * 3.0), 1e-9);

  seen = markers.count();
  const auto ball = client_.SpawnUrdf("marker_ball", SphereUrdf(0.25, 1.0), MakePose(3, 0, 30));
  ASSERT_TRUE(ball.success) << ball.message;
  spawned_.push_back("marker_ball");
  ASSERT_TRUE(WaitFor([&] { return markers.count() > seen; }, kTimeout));
  array = *markers.Get();
  ASSERT_EQ(array.markers.size(), 1u);
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::SPHERE);
  EXPECT_EQ(array.markers[0].header.frame_id, "marker_ball/base_link");
  EXPECT_DOUBLE_EQ(array.markers[0].scale.x, 0.5);

  seen = markers.count();
  ASSERT_TRUE(client_.Delete("marker_box").success);
  ASSERT_TRUE(WaitFor([&] { return markers.count() > seen; }, kTimeout));
  array = *markers.Get();
  ASSERT_EQ(array.markers.size(), 1u);
  EXPECT_EQ(array.markers[0].ns, "marker_box");
  EXPECT_EQ(array.markers[0].id, 0);
  EXPECT_EQ(array.markers[0].action, visualization_msgs::Marker::DELETE);
}

// Bad input: success = false, a message naming the problem, the body count
// unchanged and the node still answering.
// A box spawned 5 cm into the ground: the reply names the ground and the
// depth, and the box is pushed out by positions only, never faster than
// sqrt(2 g d) + 0.1 m/s, to rest on the ground.
TEST_F(NodeServicesTest, SpawnIntoOverlapIsReportedAndSeparatesWithoutLaunching) {
  const auto response =
      client_.SpawnUrdf("sunk_box", BoxUrdf(1.0, 1.0, 1.0, 1.0), MakePose(20.0, 20.0, 0.45));
  ASSERT_TRUE(response.success) << response.message;
  spawned_.push_back("sunk_box");
  EXPECT_NE(response.message.find("overlaps 'ground' by 0.05 m"), std::string::npos)
      << response.message;
  const double limit = std::sqrt(2.0 * 9.81 * 0.05) + 0.1;
  double fastest = 0.0;
  for (int step = 0; step < 480; ++step) {
    const auto stepped = client_.Step(1);
    ASSERT_TRUE(stepped.success) << stepped.message;
    const auto state = client_.GetState("sunk_box");
    const auto& v = state.twist.linear;
    fastest = std::max(fastest, std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
  }
  EXPECT_LE(fastest, limit);
  // At rest, sunk by the penetration slop (1e-4 m) the split impulse leaves.
  EXPECT_NEAR(client_.GetState("sunk_box").pose.position.z, 0.5, 1e-4 + 1e-9);
}

// A URDF cylinder (r = 0.1 m) released on its side on a static ramp tilted
// 10 degrees rolls without slipping: its centre accelerates at
// (2/3) g sin(theta), so it covers g sin(theta) t^2 / 3 in t = 1 s.
TEST_F(NodeServicesTest, UrdfCylinderRollsDownARampAtTwoThirdsGSinTheta) {
  const double theta = 10.0 * M_PI / 180.0;
  const double radius = 0.1;
  rigid_body_sim::Spawn::Request ramp;
  ramp.name = "roll_ramp";
  ramp.urdf = BoxUrdf(20.0, 4.0, 1.0, 100.0);
  ramp.is_static = true;
  ramp.pose = MakePose(40.0, 40.0, 5.0, std::cos(theta / 2), 0.0, std::sin(theta / 2), 0.0);
  ramp.friction = -1.0;
  ramp.restitution = -1.0;
  const auto ramp_reply = client_.Spawn(ramp);
  ASSERT_TRUE(ramp_reply.success) << ramp_reply.message;
  spawned_.push_back("roll_ramp");
  // Ramp normal (sin, 0, cos), downhill (cos, 0, -sin); the cylinder's axis
  // along y: the ramp's tilt times a quarter turn about x.
  const double normal[3] = {std::sin(theta), 0.0, std::cos(theta)};
  const double downhill[3] = {std::cos(theta), 0.0, -std::sin(theta)};
  const double c = std::cos(theta / 2), s = std::sin(theta / 2), h = std::sqrt(0.5);
  std::ostringstream urdf;
  urdf << "<robot name=\"roller\"><link name=\"base_link\"><inertial><mass value=\"2\"/>"
       << "<inertia ixx=\"0.02\" iyy=\"0.02\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
       << "</inertial><collision><geometry><cylinder radius=\"" << radius
       << "\" length=\"0.3\"/></geometry></collision></link></robot>";
  const double start[3] = {40.0 + 0.6 * normal[0] - 5.0 * downhill[0], 40.0,
                           5.0 + 0.6 * normal[2] - 5.0 * downhill[2]};
  const auto roller = client_.SpawnUrdf(
      "roller", urdf.str(), MakePose(start[0], start[1], start[2], c * h, c * h, s * h, -s * h));
  ASSERT_TRUE(roller.success) << roller.message;
  spawned_.push_back("roller");
  ASSERT_TRUE(client_.Step(240).success);
  const auto state = client_.GetState("roller");
  const double moved[3] = {state.pose.position.x - start[0], state.pose.position.y - start[1],
                           state.pose.position.z - start[2]};
  const double along = moved[0] * downhill[0] + moved[2] * downhill[2];
  const double expected = 9.81 * std::sin(theta) / 3.0;
  EXPECT_NEAR(along / expected, 1.0, 1e-4);
  EXPECT_NEAR(moved[0] * normal[0] + moved[2] * normal[2], 0.0, 1e-6);
}

// A 1 m cube at (3, 0, 40) and the ground: a ray along x at the cube's
// height enters its face x = 2.5 (the direction's length does not matter),
// one straight down from z = 10 meets the ground at 10 m, one up meets
// nothing; in the cube's own frame the same face is at x = -0.5.
TEST_F(NodeServicesTest, RayCastHitsTheBoxAndTheGroundInTheRequestedFrame) {
  using physics::Vec3;
  SpawnBox("ray_box", MakePose(3.0, 0.0, 40.0));
  rigid_body_sim::RayCast::Request request;
  request.origins = {node::PointToMsg(Vec3(0, 0, 40)), node::PointToMsg(Vec3(0, 0.2, 10)),
                     node::PointToMsg(Vec3(0, 0, 10))};
  request.directions = {node::VectorToMsg(Vec3(2, 0, 0)), node::VectorToMsg(Vec3(0, 0, -1)),
                        node::VectorToMsg(Vec3(0, 0, 1))};
  request.max_distance = std::numeric_limits<double>::infinity();
  auto reply = client_.RayCast(request);
  ASSERT_TRUE(reply.success) << reply.message;
  ASSERT_EQ(reply.hit.size(), 3u);
  EXPECT_TRUE(reply.hit[0]);
  EXPECT_NEAR(reply.distance[0], 2.5, 1e-12);
  EXPECT_NEAR(reply.points[0].x, 2.5, 1e-12);
  EXPECT_NEAR(reply.normals[0].x, -1.0, 1e-12);
  EXPECT_EQ(reply.hit_frames[0], "ray_box/base_link");
  EXPECT_TRUE(reply.hit[1]);
  EXPECT_NEAR(reply.distance[1], 10.0, 1e-12);
  EXPECT_NEAR(reply.normals[1].z, 1.0, 1e-12);
  EXPECT_EQ(reply.hit_frames[1], "ground");
  EXPECT_FALSE(reply.hit[2]);
  EXPECT_TRUE(std::isinf(reply.distance[2]));
  EXPECT_EQ(reply.hit_frames[2], "");

  request.frame_id = "ray_box";
  request.origins = {node::PointToMsg(Vec3(-3, 0, 0))};
  request.directions = {node::VectorToMsg(Vec3(1, 0, 0))};
  reply = client_.RayCast(request);
  ASSERT_TRUE(reply.success) << reply.message;
  EXPECT_NEAR(reply.distance[0], 2.5, 1e-12);
  EXPECT_NEAR(reply.points[0].x, -0.5, 1e-12);
  EXPECT_NEAR(reply.points[0].z, 0.0, 1e-12);

  request.ignore_models = {"ray_box"};
  reply = client_.RayCast(request);
  ASSERT_TRUE(reply.success) << reply.message;
  EXPECT_FALSE(reply.hit[0]);

  // Refused whole, naming the field.
  const auto refused = [&](rigid_body_sim::RayCast::Request bad, const std::string& field) {
    const auto answer = client_.RayCast(bad);
    EXPECT_FALSE(answer.success);
    EXPECT_NE(answer.message.find(field), std::string::npos) << answer.message;
    EXPECT_TRUE(answer.hit.empty());
  };
  rigid_body_sim::RayCast::Request bad = request;
  bad.ignore_models = {"no_such_model"};
  refused(bad, "ignore_models[0]");
  bad = request;
  bad.frame_id = "no_such_model/link";
  refused(bad, "frame_id");
  bad = request;
  bad.directions = {node::VectorToMsg(Vec3(0, 0, 0))};
  refused(bad, "directions[0]");
  bad = request;
  bad.origins[0].y = std::nan("");
  refused(bad, "origins[0]");
  bad = request;
  bad.max_distance = 0.0;
  refused(bad, "max_distance");
  bad = request;
  bad.directions.push_back(node::VectorToMsg(Vec3(1, 0, 0)));
  refused(bad, "directions");
}

TEST_F(NodeServicesTest, BadInputIsRefusedAndChangesNothing) {
  SpawnBox("existing", MakePose(0.0, 0.0, 30.0));
  const int frames = FrameCount();
  ASSERT_GT(frames, 0);
  const auto expect_refused = [&](const auto& response, const std::string& needle) {
    EXPECT_FALSE(response.success);
    EXPECT_NE(response.message.find(needle), std::string::npos)
        << "'" << response.message << "' does not mention '" << needle << "'";
    EXPECT_EQ(FrameCount(), frames);
  };
  const std::string box = BoxUrdf(1, 1, 1, 1);
  expect_refused(client_.SpawnUrdf("", box, MakePose(0, 0, 30)), "empty");
  expect_refused(client_.SpawnUrdf("existing", box, MakePose(0, 0, 30)), "already exists");
  expect_refused(client_.SpawnUrdf("bad-name", box, MakePose(0, 0, 30)), "bad character");
  expect_refused(client_.SpawnUrdf("9lives", box, MakePose(0, 0, 30)), "bad character");
  expect_refused(client_.SpawnUrdf("malformed", "<robot name='x'><link", MakePose(0, 0, 30)),
                 "malformed");
  rigid_body_sim::Spawn::Request missing;
  missing.name = "missing_file";
  missing.urdf_path = "/nonexistent/dir/missing.urdf";
  missing.pose = MakePose(0, 0, 30);
  expect_refused(client_.Spawn(missing), "/nonexistent/dir/missing.urdf");
  expect_refused(client_.SpawnUrdf("nan_pose", box, MakePose(0, std::nan(""), 30)),
                 "pose.position [0, nan, 30] is not finite");
  expect_refused(client_.SpawnUrdf("zero_quat", box, MakePose(0, 0, 30, 0, 0, 0, 0)),
                 "zero quaternion");

  expect_refused(client_.Delete("nosuch"), "no model named 'nosuch'");
  const auto get = client_.GetState("nosuch/base_link");
  EXPECT_FALSE(get.success);
  EXPECT_NE(get.message.find("no model named 'nosuch'"), std::string::npos);
  const auto get_link = client_.GetState("existing/nolink");
  EXPECT_FALSE(get_link.success);
  EXPECT_NE(get_link.message.find("no link named 'nolink'"), std::string::npos);
  rigid_body_sim::SetState::Request set;
  set.name = "nosuch";
  set.pose = MakePose(0, 0, 1);
  expect_refused(client_.SetState(set), "no model named 'nosuch'");
  set.name = "existing";
  set.pose = MakePose(0, 0, 1, 0, 0, 0, 0);
  expect_refused(client_.SetState(set), "zero quaternion");
  rigid_body_sim::ApplyWrench::Request wrench;
  wrench.name = "nosuch";
  expect_refused(client_.ApplyWrench(wrench), "no model named 'nosuch'");

  ASSERT_TRUE(client_.SetPaused(false));
  expect_refused(client_.Step(1), "paused");
  ASSERT_TRUE(client_.SetPaused(true));

  const auto physics = client_.GetPhysics();
  rigid_body_sim::SetPhysics::Request negative;
  negative.gravity = physics.gravity;
  negative.time_step = -0.01;
  negative.real_time_factor = physics.real_time_factor;
  expect_refused(client_.SetPhysics(negative), "time_step");
  EXPECT_EQ(client_.GetPhysics().time_step, physics.time_step);
  EXPECT_TRUE(client_.GetState("existing").success);
}

}  // namespace
}  // namespace rigid_body_sim::test
