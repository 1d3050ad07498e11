#include "sim_client.h"

#include <gtest/gtest.h>

#include <sstream>

#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

namespace rigid_body_sim::test {

namespace {

constexpr char kNodeNamespace[] = "/rigid_body_sim";

std::string Inertial(double mass, double ixx, double iyy, double izz) {
  std::ostringstream out;
  out << "<inertial><mass value=\"" << mass << "\"/><inertia ixx=\"" << ixx << "\" iyy=\"" << iyy
      << "\" izz=\"" << izz << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  return out.str();
}

}  // namespace

std::string BoxUrdf(double x, double y, double z, double mass) {
  std::ostringstream out;
  out.precision(17);
  out << "<robot name=\"box\"><link name=\"base_link\">"
      << Inertial(mass, mass * (y * y + z * z) / 12.0, mass * (x * x + z * z) / 12.0,
                  mass * (x * x + y * y) / 12.0)
      << "<collision><geometry><box size=\"" << x << " " << y << " " << z
      << "\"/></geometry></collision></link></robot>";
  return out.str();
}

std::string SphereUrdf(double radius, double mass) {
  std::ostringstream out;
  out.precision(17);
  const double inertia = 0.4 * mass * radius * radius;
  out << "<robot name=\"ball\"><link name=\"base_link\">"
      << Inertial(mass, inertia, inertia, inertia) << "<collision><geometry><sphere radius=\""
      << radius << "\"/></geometry></collision></link></robot>";
  return out.str();
}

geometry_msgs::Pose MakePose(double x, double y, double z, double qw, double qx, double qy,
                             double qz) {
  geometry_msgs::Pose pose;
  pose.position.x = x;
  pose.position.y = y;
  pose.position.z = z;
  pose.orientation.w = qw;
  pose.orientation.x = qx;
  pose.orientation.y = qy;
  pose.orientation.z = qz;
  return pose;
}

bool WaitFor(const std::function<bool()>& done, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (!done()) {
    if (ros::WallTime::now() > deadline || !ros::ok()) return done();
    ros::WallDuration(0.005).sleep();
  }
  return true;
}

SimClient::SimClient(bool persistent) : node_(kNodeNamespace), persistent_(persistent) {}

template <typename Service>
typename Service::Response SimClient::Call(const std::string& name,
                                           typename Service::Request request) {
  auto it = clients_.find(name);
  if (it == clients_.end()) {
    it = clients_.emplace(name, node_.serviceClient<Service>(name, persistent_)).first;
  }
  Service service;
  service.request = std::move(request);
  if (!it->second.call(service)) {
    // A persistent connection that failed is dropped, so the next call
    // connects afresh instead of failing on the dead one.
    if (persistent_) clients_.erase(it);
    service.response = typename Service::Response();
    service.response.success = false;
    service.response.message = "service call failed";
  }
  return service.response;
}

bool SimClient::WaitForServices(double timeout) {
  for (const char* name : {"spawn", "delete", "reset", "set_paused", "step", "get_state",
                           "set_state", "apply_wrench", "get_physics", "set_physics"}) {
    if (!ros::service::waitForService(node_.resolveName(name), ros::Duration(timeout))) {
      return false;
    }
  }
  return true;
}

rigid_body_sim::Spawn::Response SimClient::Spawn(const rigid_body_sim::Spawn::Request& request) {
  return Call<rigid_body_sim::Spawn>("spawn", request);
}

rigid_body_sim::Spawn::Response SimClient::SpawnUrdf(const std::string& name,
                                                     const std::string& urdf,
                                                     const geometry_msgs::Pose& pose) {
  rigid_body_sim::Spawn::Request request;
  request.name = name;
  request.urdf = urdf;
  request.pose = pose;
  request.friction = -1.0;
  request.restitution = -1.0;
  return Spawn(request);
}

rigid_body_sim::Delete::Response SimClient::Delete(const std::string& name) {
  rigid_body_sim::Delete::Request request;
  request.name = name;
  return Call<rigid_body_sim::Delete>("delete", request);
}

rigid_body_sim::GetState::Response SimClient::GetState(const std::string& name) {
  rigid_body_sim::GetState::Request request;
  request.name = name;
  return Call<rigid_body_sim::GetState>("get_state", request);
}

rigid_body_sim::RayCast::Response SimClient::RayCast(
    const rigid_body_sim::RayCast::Request& request) {
  return Call<rigid_body_sim::RayCast>("ray_cast", request);
}

rigid_body_sim::SetState::Response SimClient::SetState(
    const rigid_body_sim::SetState::Request& request) {
  return Call<rigid_body_sim::SetState>("set_state", request);
}

rigid_body_sim::ApplyWrench::Response SimClient::ApplyWrench(
    const rigid_body_sim::ApplyWrench::Request& request) {
  return Call<rigid_body_sim::ApplyWrench>("apply_wrench", request);
}

rigid_body_sim::Step::Response SimClient::Step(std::uint32_t steps) {
  rigid_body_sim::Step::Request request;
  request.steps = steps;
  return Call<rigid_body_sim::Step>("step", request);
}

bool SimClient::SetPaused(bool paused) {
  std_srvs::SetBool::Request request;
  request.data = paused;
  return Call<std_srvs::SetBool>("set_paused", request).success;
}

std_srvs::Trigger::Response SimClient::CancelStep() {
  return Call<std_srvs::Trigger>("cancel_step", {});
}

bool SimClient::Reset() { return Call<std_srvs::Trigger>("reset", {}).success; }

rigid_body_sim::GetPhysics::Response SimClient::GetPhysics() {
  rigid_body_sim::GetPhysics service;
  if (!node_.serviceClient<rigid_body_sim::GetPhysics>("get_physics").call(service)) {
    ADD_FAILURE() << "get_physics call failed";
  }
  return service.response;
}

rigid_body_sim::SetPhysics::Response SimClient::SetPhysics(
    const rigid_body_sim::SetPhysics::Request& request) {
  return Call<rigid_body_sim::SetPhysics>("set_physics", request);
}

}  // namespace rigid_body_sim::test

// Every rostest client: gtest plus a ROS node whose callbacks run on two
// spinner threads.
int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rigid_body_sim_test", ros::init_options::AnonymousName);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
