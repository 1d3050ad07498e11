// libFuzzer harness for the joint topics' parsing (joint_requests.h): the
// bytes become a joint_command or a joint_trajectory for a model of four
// joints (a revolute, a prismatic, a continuous one and a mimic), with
// names from a pool that holds unknown, repeated and mimic names, list
// lengths that may disagree, and doubles of any bit pattern. A refusal must
// name something; whatever is accepted must index real joints, hold values
// within the request limits, and sample finite commands at any time.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "rigid_body_sim/node/joint_requests.h"

namespace {

namespace node = rigid_body_sim::node;

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::uint8_t Byte() {
    if (size == 0) return 0;
    --size;
    return *data++;
  }
  double Double() {
    double value = 0.0;
    if (size >= sizeof(value)) {
      std::memcpy(&value, data, sizeof(value));
      data += sizeof(value);
      size -= sizeof(value);
    }
    return value;
  }
  std::vector<double> Doubles() {
    std::vector<double> values(Byte() % 6);
    for (double& value : values) value = Double();
    return values;
  }
};

const node::ModelJoints& Joints() {
  static const node::ModelJoints joints = [] {
    node::ModelJoints made;
    made.model = "fuzzed";
    made.names = {"shoulder", "slider", "wheel", "finger"};
    made.prismatic = {false, true, false, true};
    made.leaders = {"", "", "", "slider"};
    for (std::size_t k = 0; k < made.names.size(); ++k) {
      made.index.emplace(made.names[k], static_cast<int>(k));
    }
    return made;
  }();
  return joints;
}

std::vector<std::string> Names(Reader* in) {
  static const char* const kPool[] = {"shoulder", "slider", "wheel", "finger", "", "nope"};
  std::vector<std::string> names(in->Byte() % 6);
  for (std::string& name : names) name = kPool[in->Byte() % 6];
  return names;
}

void FuzzCommand(Reader* in, const node::RequestLimits& limits) {
  node::JointCommandRequest request;
  request.names = Names(in);
  request.position = in->Doubles();
  request.velocity = in->Doubles();
  request.effort = in->Doubles();
  const auto parsed = node::ParseJointCommand(Joints(), request, limits);
  if (!parsed.ok()) {
    if (parsed.message().empty()) std::abort();
    return;
  }
  for (const auto& [joint, command] : *parsed) {
    if (joint < 0 || joint >= 3) std::abort();  // never the mimic
    if (!(std::abs(command.position) <= node::kMaxJointPosition)) std::abort();
    if (!std::isfinite(command.velocity) || !std::isfinite(command.effort)) std::abort();
  }
}

void FuzzTrajectory(Reader* in, const node::RequestLimits& limits) {
  node::JointTrajectoryRequest request;
  request.joint_names = Names(in);
  request.points.resize(in->Byte() % 8);
  for (auto& point : request.points) {
    point.positions = in->Doubles();
    point.velocities = in->Doubles();
    point.time_from_start = in->Double();
  }
  auto parsed = node::ParseJointTrajectory(Joints(), request, limits);
  if (!parsed.ok()) {
    if (parsed.message().empty()) std::abort();
    return;
  }
  node::TrajectoryPoint start;
  for (std::size_t k = 0; k < parsed->joints.size(); ++k) {
    start.positions.push_back(0.1 * static_cast<double>(k));
    start.velocities.push_back(0.0);
  }
  if (!parsed.value().plan.Begin(start).ok()) std::abort();
  for (const double t :
       {-1.0, 0.0, in->Double(), 0.5 * parsed->plan.duration(), parsed->plan.duration(), 1e300}) {
    const node::TrajectorySample sample = parsed->plan.Sample(t);
    if (sample.positions.size() != parsed->joints.size()) std::abort();
    for (const double value : sample.positions) {
      if (!std::isfinite(value)) std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  node::RequestLimits limits;
  limits.max_trajectory_points = 6;
  if (in.Byte() % 2 == 0) {
    FuzzCommand(&in, limits);
  } else {
    FuzzTrajectory(&in, limits);
  }
  return 0;
}
