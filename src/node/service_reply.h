// How a service of the node refuses a request: success false, the reason
// in the response, and the same line in rosconsole.
#ifndef RIGID_BODY_SIM_NODE_SERVICE_REPLY_H_
#define RIGID_BODY_SIM_NODE_SERVICE_REPLY_H_

#include <string>

#include <ros/console.h>

namespace rigid_body_sim::node {

// Returns true: the call was answered (with a refusal).
template <typename Response>
bool Fail(Response& response, const std::string& message, const char* service) {
  response.success = false;
  response.message = message;
  ROS_WARN("~%s refused: %s", service, message.c_str());
  return true;
}

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_SERVICE_REPLY_H_
