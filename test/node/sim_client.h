// Helpers for the rostests: service calls to the node, test URDFs and
// bounded waits.
#ifndef RIGID_BODY_SIM_TEST_NODE_SIM_CLIENT_H_
#define RIGID_BODY_SIM_TEST_NODE_SIM_CLIENT_H_

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <geometry_msgs/Pose.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "rigid_body_sim/ApplyWrench.h"
#include "rigid_body_sim/Contacts.h"
#include "rigid_body_sim/Delete.h"
#include "rigid_body_sim/GetPhysics.h"
#include "rigid_body_sim/GetState.h"
#include "rigid_body_sim/ModelStates.h"
#include "rigid_body_sim/RayCast.h"
#include "rigid_body_sim/SetPhysics.h"
#include "rigid_body_sim/SetState.h"
#include "rigid_body_sim/Spawn.h"
#include "rigid_body_sim/Step.h"

namespace rigid_body_sim::test {

// A one-link model 'base_link' with a box collision of full edge lengths
// (x, y, z) m and the box's exact inertia for `mass` kg.
std::string BoxUrdf(double x, double y, double z, double mass);
// A one-link model 'base_link' with a sphere of `radius` m and `mass` kg.
std::string SphereUrdf(double radius, double mass);

geometry_msgs::Pose MakePose(double x, double y, double z, double qw = 1.0, double qx = 0.0,
                             double qy = 0.0, double qz = 0.0);

// Polls `done` every 5 ms of wall time until it holds or `timeout` s of
// wall time have passed; returns its last value. Callbacks run on the
// test's AsyncSpinner meanwhile.
bool WaitFor(const std::function<bool()>& done, double timeout);

// Service calls to the node under /rigid_body_sim. A failed transport
// gives success = false and the message "service call failed". A persistent
// client keeps one connection per service; roscpp's per-call connections
// fail now and then under a tight loop of calls (ros/ros_comm#1976).
class SimClient {
 public:
  explicit SimClient(bool persistent = false);
  bool WaitForServices(double timeout);

  rigid_body_sim::Spawn::Response Spawn(const rigid_body_sim::Spawn::Request& request);
  rigid_body_sim::Spawn::Response SpawnUrdf(const std::string& name, const std::string& urdf,
                                            const geometry_msgs::Pose& pose);
  rigid_body_sim::Delete::Response Delete(const std::string& name);
  rigid_body_sim::GetState::Response GetState(const std::string& name);
  rigid_body_sim::RayCast::Response RayCast(const rigid_body_sim::RayCast::Request& request);
  rigid_body_sim::SetState::Response SetState(const rigid_body_sim::SetState::Request& request);
  rigid_body_sim::ApplyWrench::Response ApplyWrench(
      const rigid_body_sim::ApplyWrench::Request& request);
  rigid_body_sim::Step::Response Step(std::uint32_t steps);
  bool SetPaused(bool paused);
  std_srvs::Trigger::Response CancelStep();
  bool Reset();
  rigid_body_sim::GetPhysics::Response GetPhysics();
  rigid_body_sim::SetPhysics::Response SetPhysics(const rigid_body_sim::SetPhysics::Request& r);

 private:
  template <typename Service>
  typename Service::Response Call(const std::string& name, typename Service::Request request);

  ros::NodeHandle node_;
  bool persistent_;
  std::map<std::string, ros::ServiceClient> clients_;
};

// Keeps the latest message of a topic and counts arrivals. The callback
// owns what it writes: roscpp may still run a callback it had dequeued
// after the subscriber is destroyed, so the state outlives this object
// until roscpp lets go of the callback.
template <typename Message>
class Latest {
 public:
  Latest(ros::NodeHandle& node, const std::string& topic) : state_(std::make_shared<State>()) {
    subscriber_ = node.subscribe<Message>(
        topic, 100, [state = state_](const boost::shared_ptr<const Message>& m) {
          std::lock_guard<std::mutex> lock(state->mutex);
          state->latest = *m;
          ++state->count;
        });
  }
  std::optional<Message> Get() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    return state_->latest;
  }
  std::uint64_t count() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    return state_->count;
  }
  // The first message that arrives after this call, within `timeout` s.
  std::optional<Message> Next(double timeout) const {
    const std::uint64_t seen = count();
    if (!WaitFor([&] { return count() > seen; }, timeout)) return std::nullopt;
    return Get();
  }

 private:
  struct State {
    std::mutex mutex;
    std::optional<Message> latest;  // guarded by mutex
    std::uint64_t count = 0;        // guarded by mutex
  };
  std::shared_ptr<State> state_;
  ros::Subscriber subscriber_;
};

}  // namespace rigid_body_sim::test

#endif  // RIGID_BODY_SIM_TEST_NODE_SIM_CLIENT_H_
