// rigid_body_sim_node: the simulator as a ROS node (see sim_node.h).
#include <ros/ros.h>

#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/options.h"
#include "rigid_body_sim/node/sim_node.h"

int main(int argc, char** argv) {
  using rigid_body_sim::node::NodeOptions;
  ros::init(argc, argv, rigid_body_sim::node::names::kDefaultNodeName);
  ros::NodeHandle private_node("~");
  const rigid_body_sim::physics::Result<NodeOptions> options =
      rigid_body_sim::node::ReadNodeOptions(private_node);
  if (!options.ok()) {
    ROS_FATAL("invalid parameters: %s", options.message().c_str());
    return 1;
  }
  rigid_body_sim::node::WriteNodeOptions(*options, private_node);
  rigid_body_sim::node::SimNode node(*options, ros::NodeHandle(), private_node);
  ros::AsyncSpinner spinner(4);
  spinner.start();
  if (const rigid_body_sim::physics::Status status = node.Start(); !status.ok()) {
    ROS_FATAL("%s", status.message().c_str());
    return 1;
  }
  ros::waitForShutdown();
  return 0;
}
