// A battery of hostile requests through the node's ROS interface: each is
// answered success = false with a message naming the field, the node stays
// alive and the world is unchanged. Then a 100,000-step ~step that other
// services answer during and ~cancel_step stops, and a body frozen by the
// step guard while its neighbour falls on. The launch file raises ~max_force
// to 1e100 N so that a wrench the validation lets through can overflow a
// step.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr double kTimeout = 20.0;  // s of wall time for any single wait
constexpr double kG = 9.81;
// Spinning boxes that keep a 100,000-step ~step busy for a second or more
// on an idle machine; the test cancels it at 40 % at the latest.
constexpr int kSpinners = 400;
constexpr double kPublishRate = 50.0;  // Hz, the node's default ~publish_rate

std::string OneLink(const std::string& geometry) {
  return "<robot name='r'><link name='base_link'><collision><geometry>" + geometry +
         "</geometry></collision></link></robot>";
}

// A fixed chain of `links` 0.1 m boxes.
std::string Chain(int links) {
  std::string xml = "<robot name='chain'>";
  for (int i = 0; i < links; ++i) {
    xml += "<link name='l" + std::to_string(i) +
           "'><collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision></link>";
    if (i > 0) {
      xml += "<joint name='j" + std::to_string(i) + "' type='fixed'><parent link='l" +
             std::to_string(i - 1) + "'/><child link='l" + std::to_string(i) + "'/></joint>";
    }
  }
  return xml + "</robot>";
}

class NodeHostileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(client_.WaitForServices(kTimeout));
    ASSERT_TRUE(client_.SetPaused(true));
    ASSERT_TRUE(client_.Reset());
    ASSERT_TRUE(SetPhysics(1.0 / 240.0, 1.0).success);
    const auto spawned = client_.SpawnUrdf("anchor", BoxUrdf(1, 1, 1, 1), MakePose(0, 0, 5));
    ASSERT_TRUE(spawned.success) << spawned.message;
    ASSERT_TRUE(client_.Step(3).success);  // in flight: a twist that must not change
  }
  void TearDown() override {
    client_.Delete("anchor");
    client_.Delete("neighbour");
    client_.Delete("light");
    SimClient deleter(/*persistent=*/true);
    for (int i = 0; i < kSpinners; ++i) deleter.Delete("spinner" + std::to_string(i));
    client_.SetPaused(false);
  }

  struct Snapshot {
    double sim_time = 0.0;
    rigid_body_sim::GetState::Response anchor;
    rigid_body_sim::GetPhysics::Response physics;
  };
  Snapshot Take() {
    Snapshot snapshot;
    snapshot.sim_time = client_.Step(0).sim_time;
    snapshot.anchor = client_.GetState("anchor");
    snapshot.physics = client_.GetPhysics();
    return snapshot;
  }
  // The reply refused the request naming every one of `words`, and the
  // node still answers with the world as it was.
  template <typename Response>
  void ExpectRefused(const Response& reply, std::initializer_list<const char*> words,
                     const std::string& model = "") {
    EXPECT_FALSE(reply.success);
    for (const char* word : words) {
      EXPECT_NE(reply.message.find(word), std::string::npos)
          << "'" << word << "' not in: " << reply.message;
    }
    const Snapshot now = Take();
    ASSERT_TRUE(now.anchor.success) << "the node no longer answers: " << now.anchor.message;
    EXPECT_EQ(now.sim_time, before_.sim_time);
    EXPECT_EQ(now.anchor.pose, before_.anchor.pose);
    EXPECT_EQ(now.anchor.twist, before_.anchor.twist);
    EXPECT_EQ(now.physics.time_step, before_.physics.time_step);
    EXPECT_EQ(now.physics.real_time_factor, before_.physics.real_time_factor);
    EXPECT_EQ(now.physics.gravity, before_.physics.gravity);
    if (!model.empty()) {
      EXPECT_FALSE(client_.GetState(model).success) << model << " exists";
    }
  }
  rigid_body_sim::Spawn::Response SpawnXml(const std::string& name, const std::string& xml) {
    return client_.SpawnUrdf(name, xml, MakePose(0, 0, 20));
  }
  rigid_body_sim::SetPhysics::Response SetPhysics(double time_step, double factor,
                                                  double gravity_z = -kG) {
    rigid_body_sim::SetPhysics::Request request;
    request.gravity.z = gravity_z;
    request.time_step = time_step;
    request.real_time_factor = factor;
    return client_.SetPhysics(request);
  }
  rigid_body_sim::ApplyWrench::Response Wrench(double force, double torque, double duration,
                                               double point = 0.0) {
    rigid_body_sim::ApplyWrench::Request request;
    request.name = "anchor";
    request.point.x = point;
    request.wrench.force.x = force;
    request.wrench.torque.z = torque;
    request.duration = duration;
    return client_.ApplyWrench(request);
  }
  rigid_body_sim::SetState::Response SetState(const geometry_msgs::Pose& pose, double speed) {
    rigid_body_sim::SetState::Request request;
    request.name = "anchor";
    request.pose = pose;
    request.twist.linear.x = speed;
    return client_.SetState(request);
  }

  ros::NodeHandle node_{"/rigid_body_sim"};
  SimClient client_;
  Snapshot before_;
};

TEST_F(NodeHostileTest, HostileSpawnsAreRefusedByField) {
  before_ = Take();
  ExpectRefused(SpawnXml("tiny", OneLink("<box size='1e-7 1e-7 1'/>")),
                {"<box> size", "1e-07", "[0.0001, 10000]"}, "tiny");
  ExpectRefused(SpawnXml("long", OneLink("<cylinder radius='0.01' length='1e5'/>")),
                {"<cylinder> length", "100000", "[0.0001, 10000]"}, "long");
  ExpectRefused(SpawnXml("thin", OneLink("<cylinder radius='0.01' length='100'/>")),
                {"<cylinder>", "aspect ratio 5000", "1000"}, "thin");
  ExpectRefused(SpawnXml("nan_radius", OneLink("<cylinder radius='nan' length='1'/>")),
                {"<cylinder> radius='nan'", "not a finite number"}, "nan_radius");
  ExpectRefused(SpawnXml("huge_sphere", OneLink("<sphere radius='1e300'/>")),
                {"<sphere> radius", "1e+300"}, "huge_sphere");
  ExpectRefused(SpawnXml("chain", Chain(10000)), {"10000 links", "max_links_per_model 1000"},
                "chain");
  // urdfdom would log this value as a printf format: "%s" read off the stack.
  const std::string link = "<collision><geometry><box size='1 1 1'/></geometry></collision>";
  ExpectRefused(SpawnXml("printf", "<robot name='printf'><link name='a'>" + link +
                                       "</link><link name='b'>" + link +
                                       "</link><joint name='j' type='continuous'><parent "
                                       "link='a'/><child link='b'/><calibration rising='" +
                                       "%s%s%s%s%s%s%s%s%s%s%s%s%n'/></joint></robot>"),
                {"rising value", "?s?s?s?n"}, "printf");
  rigid_body_sim::Spawn::Request zero;
  zero.name = "zero";
  zero.urdf_path = "/dev/zero";
  zero.pose = MakePose(0, 0, 20);
  ExpectRefused(client_.Spawn(zero), {"/dev/zero", "not a regular file"}, "zero");
  const std::string box = BoxUrdf(1, 1, 1, 1);
  ExpectRefused(client_.SpawnUrdf("far", box, MakePose(1e300, 0, 0)),
                {"pose.position", "1e+300", "[0, 1e+06] m"}, "far");
  rigid_body_sim::Spawn::Request fast;
  fast.name = "fast";
  fast.urdf = box;
  fast.pose = MakePose(0, 0, 20);
  fast.twist.angular.z = 1e300;
  ExpectRefused(client_.Spawn(fast), {"twist.angular", "1e+300", "[0, 10000] rad/s"}, "fast");
  fast.twist.angular.z = 0.0;
  fast.friction = std::nan("");
  ExpectRefused(client_.Spawn(fast), {"friction nan", "[0, 1000]"}, "fast");
}

TEST_F(NodeHostileTest, HostileStateWrenchAndPhysicsAreRefusedByField) {
  before_ = Take();
  ExpectRefused(SetState(MakePose(0, 0, 5), 1e300), {"twist.linear", "1e+300", "10000"});
  ExpectRefused(SetState(MakePose(0, 0, 5, 1e300, 1e300, 1e300, 1e300), 0.0),
                {"pose.orientation", "norm 2e+300", "[1e-09, 1e+09]"});
  ExpectRefused(SetState(MakePose(0, 0, 5, 0, 0, 0, 0), 0.0),
                {"pose.orientation", "zero quaternion"});
  ExpectRefused(Wrench(1e300, 0, 0), {"wrench.force", "1e+300", "1e+100"});
  ExpectRefused(Wrench(0, 1e300, 0), {"wrench.torque", "1e+300", "1e+09"});
  ExpectRefused(Wrench(1, 0, 1e300), {"duration", "1e+300", "[0, 3600] s"});
  ExpectRefused(Wrench(1, 0, std::nan("")), {"duration", "nan"});
  ExpectRefused(Wrench(1, 0, 0, 1e300), {"point", "1e+300"});
  ExpectRefused(SetPhysics(1e10, 1.0), {"time_step", "1e+10", "[1e-05, 0.1] s"});
  ExpectRefused(SetPhysics(1e-300, 1.0), {"time_step", "1e-300"});
  ExpectRefused(SetPhysics(0.5, 1.0), {"time_step", "0.5"});
  ExpectRefused(SetPhysics(before_.physics.time_step, 1e-13),
                {"real_time_factor", "1e-13", "[0.001, 1e+06]"});
  ExpectRefused(SetPhysics(before_.physics.time_step, 1.0, 1e300), {"gravity", "1e+300"});
  ExpectRefused(client_.Step(1000000000), {"steps 1000000000", "[0, 100000]"});
  // After the refused time step of 1e10 s, a step is an ordinary step.
  const auto stepped = client_.Step(1);
  ASSERT_TRUE(stepped.success) << stepped.message;
  EXPECT_NEAR(stepped.sim_time, before_.sim_time + before_.physics.time_step, 1e-12);
}

// kSpinners boxes spinning in free space (no gravity) stay awake, so
// 100,000 steps take seconds. Meanwhile ~get_state answers within 50 ms (p99), ~states
// keeps coming, and ~cancel_step stops the call, which says how many steps
// ran; sim time moved by exactly that many steps.
TEST_F(NodeHostileTest, LongStepLetsOthersInAndIsCancelled) {
  ASSERT_TRUE(SetPhysics(1.0 / 240.0, 1.0, 0.0).success);
  // One connection for hundreds of calls: roscpp's per-call connections
  // fail now and then in a tight loop (sim_client.h).
  SimClient spawner(/*persistent=*/true);
  for (int i = 0; i < kSpinners; ++i) {
    rigid_body_sim::Spawn::Request spinner;
    spinner.name = "spinner" + std::to_string(i);
    spinner.urdf = BoxUrdf(0.2, 0.4, 0.6, 1.0);
    spinner.pose = MakePose(3.0 * (i % 20), 3.0 * (i / 20), 10);
    spinner.twist.angular.x = 1.0 + 0.005 * i;
    spinner.twist.angular.y = 2.0;
    spinner.friction = -1;
    spinner.restitution = -1;
    const auto spawned = spawner.Spawn(spinner);
    ASSERT_TRUE(spawned.success) << spawned.message;
  }
  const double start_time = client_.Step(0).sim_time;
  Latest<rigid_body_sim::ModelStates> states(node_, "states");
  auto long_step = std::async(std::launch::async, [] {
    SimClient own_client(/*persistent=*/true);
    return own_client.Step(100000);
  });
  // Whatever ends this test, the long call ends too: ~set_paused false stops
  // it, and the future's destructor would otherwise wait for all its steps.
  struct StopLongStep {
    std::future<rigid_body_sim::Step::Response>& call;
    ~StopLongStep() {
      if (call.valid() && call.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
        SimClient().SetPaused(false);
      }
    }
  } stop_long_step{long_step};
  const auto sim_time = [&] {
    const auto message = states.Get();
    return message ? message->header.stamp.toSec() : start_time;
  };
  // The call has started once ~states shows sim time past start_time; a
  // cancel sent before that finds no call in progress, and is refused.
  if (!WaitFor([&] { return sim_time() > start_time; }, kTimeout)) {
    const bool ended = long_step.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    FAIL() << "~states never showed the 100,000-step call running; the call "
           << (ended ? "ended: '" + long_step.get().message + "'" : std::string("is pending"));
  }
  const std::uint64_t states_before = states.count();
  std::vector<double> latencies;
  // Watched for 0.5 s, or until ~states shows 40 % of the steps done, so
  // that the call is still running when it is cancelled however fast the
  // machine.
  const double cancel_at = start_time + 0.4 * 100000 / 240.0;
  const ros::WallTime watch_start = ros::WallTime::now();
  const ros::WallTime end = watch_start + ros::WallDuration(0.5);
  while (ros::WallTime::now() < end && sim_time() < cancel_at) {
    const ros::WallTime sent = ros::WallTime::now();
    ASSERT_TRUE(client_.GetState("spinner0").success);
    latencies.push_back((ros::WallTime::now() - sent).toSec());
  }
  const std::uint64_t states_during = states.count() - states_before;
  const double watched = (ros::WallTime::now() - watch_start).toSec();
  const auto cancelled = client_.CancelStep();
  EXPECT_TRUE(cancelled.success) << cancelled.message;
  ASSERT_EQ(long_step.wait_for(std::chrono::seconds(20)), std::future_status::ready);
  const auto reply = long_step.get();
  EXPECT_FALSE(reply.success);
  EXPECT_NE(reply.message.find("stopped by ~cancel_step after "), std::string::npos)
      << reply.message;
  ASSERT_NE(reply.message.find("after "), std::string::npos) << reply.message;
  const std::string count_text = reply.message.substr(reply.message.find("after ") + 6);
  const long steps_run = std::stol(count_text);
  EXPECT_GT(steps_run, 0);
  EXPECT_LT(steps_run, 100000);
  EXPECT_NE(reply.message.find(" of 100000 steps"), std::string::npos);
  EXPECT_NEAR(reply.sim_time - start_time, steps_run / 240.0, 1e-9);
  EXPECT_FALSE(client_.CancelStep().success);  // nothing left to cancel

  std::sort(latencies.begin(), latencies.end());
  ASSERT_GE(latencies.size(), 10u);
  const double p99 = latencies[static_cast<std::size_t>(0.99 * (latencies.size() - 1))];
  EXPECT_LT(p99, 0.050) << latencies.size() << " calls";
  std::printf(
      "[measured] ~get_state during a 100,000-step ~step: p99 %.2f ms, max %.2f ms over "
      "%zu calls; %llu ~states meanwhile; cancelled after %ld steps\n",
      1e3 * p99, 1e3 * latencies.back(), latencies.size(),
      static_cast<unsigned long long>(states_during), steps_run);
  // ~states keeps its ~publish_rate (50 Hz by default) while the call runs:
  // the call publishes between its chunks of at most 10 ms or one step.
  EXPECT_GE(static_cast<double>(states_during), 0.7 * kPublishRate * watched - 1.0)
      << "over " << watched << " s";
  ASSERT_TRUE(SetPhysics(1.0 / 240.0, 1.0, -kG).success);
}

// A 1 g box given 1e100 N (allowed by this launch's ~max_force): dv = dt F / m
// is 4e100 m/s in one step, beyond the step guard's 1e100. It is frozen where
// it was, listed in ~states' frozen and named by ~get_state; the 1 kg box
// beside it falls freely, z = z0 - g t^2 / 2 exactly as the integrator
// gives it. ~set_state revives the frozen one.
TEST_F(NodeHostileTest, OverflowingBodyIsFrozenAndNeighbourFallsOn) {
  ASSERT_TRUE(
      client_.SpawnUrdf("light", BoxUrdf(0.1, 0.1, 0.1, 0.001), MakePose(0, 5, 50)).success);
  ASSERT_TRUE(client_.SpawnUrdf("neighbour", BoxUrdf(1, 1, 1, 1), MakePose(1, 5, 50)).success);
  rigid_body_sim::ApplyWrench::Request wrench;
  wrench.name = "light";
  wrench.point = MakePose(0, 5, 50).position;
  wrench.wrench.force.x = 1e100;
  const auto applied = client_.ApplyWrench(wrench);
  ASSERT_TRUE(applied.success) << applied.message;
  const double t0 = client_.Step(0).sim_time;
  Latest<rigid_body_sim::ModelStates> states(node_, "states");
  ASSERT_TRUE(client_.Step(240).success);
  const auto light = client_.GetState("light");
  ASSERT_TRUE(light.success);
  EXPECT_NEAR(light.pose.position.x, 0.0, 1e-12);
  EXPECT_NEAR(light.pose.position.y, 5.0, 1e-12);
  EXPECT_NEAR(light.pose.position.z, 50.0, 1e-12);
  EXPECT_EQ(light.twist.linear.x, 0.0);
  EXPECT_EQ(light.twist.linear.z, 0.0);
  EXPECT_NE(light.message.find("frozen"), std::string::npos) << light.message;
  const auto neighbour = client_.GetState("neighbour");
  ASSERT_TRUE(neighbour.success);
  EXPECT_TRUE(neighbour.message.empty()) << neighbour.message;
  const double t = client_.Step(0).sim_time - t0;
  EXPECT_NEAR(t, 1.0, 1e-9);
  EXPECT_NEAR(neighbour.pose.position.x, 1.0, 1e-12);
  EXPECT_NEAR(neighbour.pose.position.z, 50.0 - 0.5 * kG * t * t, 1e-9);
  EXPECT_NEAR(neighbour.twist.linear.z, -kG * t, 1e-9);
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto message = states.Get();
        return message && std::find(message->frozen.begin(), message->frozen.end(), "light") !=
                              message->frozen.end();
      },
      kTimeout));

  rigid_body_sim::SetState::Request revive;
  revive.name = "light";
  revive.pose = MakePose(0, 5, 50);
  ASSERT_TRUE(client_.SetState(revive).success);
  ASSERT_TRUE(client_.Step(1).success);
  const auto revived = client_.GetState("light");
  EXPECT_TRUE(revived.message.empty()) << revived.message;
  EXPECT_LT(revived.pose.position.z, 50.0);
}

}  // namespace
}  // namespace rigid_body_sim::test
