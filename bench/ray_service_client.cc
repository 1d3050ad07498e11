// The round trip of one ~ray_cast call of 100,000 rays through the running
// node, from a roscpp client: ray_bench's scene (a terrain of 99,458
// triangles, written as a binary STL file, and 1,000 static boxes of
// 0.5 m) spawned through ~spawn, and ray_bench's rays, cast down at random
// slants from 3 m.
// bench/ray_service_bench.py --client runs it under a master and a node of
// its own (sim.launch: one physics thread, ~threads' default). Prints the
// best round trip, what this client spends serialising the request and
// deserialising the answer (measured apart on the same messages), the rest
// (the node's own time and the transport), and the first rays' hits against
// the exact first hit computed here apart from the node (the boxes by their
// slabs, the terrain by every triangle, the ground plane z = 0). Exits with 1
// when a hit differs from it by more than 1e-9 m.
//
// Usage: ray_service_client [rays] [calls] [checked]   (100000 5 1000)
#include <ros/ros.h>
#include <ros/serialization.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "ray_scene.h"
#include "rigid_body_sim/RayCast.h"
#include "rigid_body_sim/Spawn.h"

namespace {

using Vec3 = Eigen::Vector3d;

using rigid_body_sim::bench::kRayBoxes;
using rigid_body_sim::bench::kRayReach;
using Scene = rigid_body_sim::bench::RayScene;
using Ray = rigid_body_sim::bench::SceneRay;

constexpr double kTolerance = 1e-9;  // m, the acceptance's
constexpr char kNode[] = "/rigid_body_sim";

// The terrain as a binary STL file (Burns 1989, the StereoLithography
// Interface Specification: an 80-byte header, a 32-bit count, then per
// triangle a normal and three corners in 32-bit floats and a 16-bit
// attribute), whose floats the node's loader reads as they are, in a file a
// fifth of an OBJ's size.
bool WriteStl(const Scene& scene, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  const char header[80] = "ray_service_client terrain";
  out.write(header, sizeof(header));
  const std::uint32_t count = static_cast<std::uint32_t>(scene.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), sizeof(count));
  for (const Eigen::Vector3i& triangle : scene.triangles) {
    float values[12] = {0.0f, 0.0f, 0.0f};  // the normal: the reader's to work out
    for (int k = 0; k < 3; ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        values[3 + 3 * k + axis] = static_cast<float>(scene.vertices[triangle[k]][axis]);
      }
    }
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(values), sizeof(values));
    out.write(reinterpret_cast<const char*>(&attribute), sizeof(attribute));
  }
  return static_cast<bool>(out);
}

bool Spawn(ros::ServiceClient& spawn, const std::string& name, const std::string& urdf,
           const Vec3& position) {
  rigid_body_sim::Spawn call;
  call.request.name = name;
  call.request.urdf = urdf;
  call.request.pose.position.x = position.x();
  call.request.pose.position.y = position.y();
  call.request.pose.position.z = position.z();
  call.request.pose.orientation.w = 1.0;
  call.request.is_static = true;
  call.request.friction = -1.0;
  call.request.restitution = -1.0;
  if (spawn.call(call) && call.response.success) return true;
  std::fprintf(stderr, "ray_service_client: %s refused: %s\n", name.c_str(),
               call.response.message.c_str());
  return false;
}

bool SpawnScene(ros::NodeHandle& node, const Scene& scene, const std::string& mesh_path) {
  const std::string spawn_name = std::string(kNode) + "/spawn";
  if (!ros::service::waitForService(spawn_name, ros::Duration(60.0))) {
    std::fprintf(stderr, "ray_service_client: no %s\n", spawn_name.c_str());
    return false;
  }
  ros::ServiceClient spawn = node.serviceClient<rigid_body_sim::Spawn>(spawn_name, true);
  const std::string terrain =
      "<robot name=\"terrain\"><link name=\"ground\"><collision><geometry><mesh "
      "filename=\"file://" +
      mesh_path + "\"/></geometry></collision></link></robot>";
  if (!Spawn(spawn, "terrain", terrain, Vec3::Zero())) return false;
  const std::string box =
      "<robot name=\"box\"><link name=\"box\"><collision><geometry><box size=\"0.5 0.5 0.5\"/>"
      "</geometry></collision></link></robot>";
  for (int k = 0; k < kRayBoxes; ++k) {
    if (!Spawn(spawn, "box_" + std::to_string(k), box, scene.box_centres[k])) return false;
  }
  return true;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// This client's own share of a call, each the best of three like the round
// trip: the request serialised, the answer deserialised.
void ClientShare(const rigid_body_sim::RayCast& call, double* encode, double* decode) {
  namespace ser = ros::serialization;
  *encode = *decode = 1e30;
  const ros::SerializedMessage answer = ser::serializeMessage(call.response);
  for (int run = 0; run < 3; ++run) {
    auto start = std::chrono::steady_clock::now();
    const ros::SerializedMessage request = ser::serializeMessage(call.request);
    *encode = std::min(*encode, Seconds(start));
    start = std::chrono::steady_clock::now();
    rigid_body_sim::RayCast::Response response;
    // The length prefix first, as the transport hands it over.
    ser::IStream stream(answer.message_start, answer.num_bytes - 4);
    ser::deserialize(stream, response);
    *decode = std::min(*decode, Seconds(start));
  }
}

// The largest difference of the first `checked` answers from the exact first
// hits (ExactRayDistance, the ground plane included), in distance or point
// (m); -1 when a hit and a miss differ.
double LargestError(const Scene& scene, const rigid_body_sim::RayCast::Response& answer,
                    int checked) {
  double error = 0.0;
  for (int i = 0; i < checked; ++i) {
    const Ray& ray = scene.rays[i];
    const double exact = rigid_body_sim::bench::ExactRayDistance(scene, ray, true);
    if (answer.hit[i] != (exact >= 0.0)) return -1.0;
    if (!answer.hit[i]) continue;
    const Vec3 point(answer.points[i].x, answer.points[i].y, answer.points[i].z);
    error = std::max({error, std::abs(answer.distance[i] - exact),
                      (point - (ray.origin + exact * ray.direction)).norm()});
  }
  return error;
}

// The first `checked` answers against the exact first hits; false when one
// is off by more than kTolerance, or a hit and a miss differ.
bool Check(const Scene& scene, const rigid_body_sim::RayCast::Response& answer, int checked) {
  checked = std::min<int>(checked, scene.rays.size());
  const double error = LargestError(scene, answer, checked);
  std::printf(
      "  the first %d hits against the exact ones (boxes by slabs, every triangle, the "
      "ground): largest error %.1e m (-1: a hit and a miss differ)\n",
      checked, error);
  return error >= 0.0 && error <= kTolerance;
}

int Run(ros::NodeHandle& node, int ray_count, int calls, int checked) {
  const Scene scene = rigid_body_sim::bench::MakeRayScene(ray_count, true);
  char directory[] = "/tmp/ray_service_client_XXXXXX";
  if (mkdtemp(directory) == nullptr) return 1;
  const std::string stl_path = std::string(directory) + "/terrain.stl";
  const bool spawned = WriteStl(scene, stl_path) && SpawnScene(node, scene, stl_path);
  std::remove(stl_path.c_str());
  std::remove(directory);
  if (!spawned) return 1;
  rigid_body_sim::RayCast call;
  call.request.max_distance = kRayReach;
  for (const Ray& ray : scene.rays) {
    geometry_msgs::Point origin;
    origin.x = ray.origin.x();
    origin.y = ray.origin.y();
    origin.z = ray.origin.z();
    geometry_msgs::Vector3 direction;
    direction.x = ray.direction.x();
    direction.y = ray.direction.y();
    direction.z = ray.direction.z();
    call.request.origins.push_back(origin);
    call.request.directions.push_back(direction);
  }
  ros::ServiceClient cast =
      node.serviceClient<rigid_body_sim::RayCast>(std::string(kNode) + "/ray_cast", true);
  double best = 1e30;
  for (int k = 0; k < calls; ++k) {
    const auto start = std::chrono::steady_clock::now();
    if (!cast.call(call) || !call.response.success) {
      std::fprintf(stderr, "ray_service_client: ray_cast failed: %s\n",
                   call.response.message.c_str());
      return 1;
    }
    best = std::min(best, Seconds(start));
  }
  double encode = 0.0;
  double decode = 0.0;
  ClientShare(call, &encode, &decode);
  int threads = -1;
  ros::param::get(std::string(kNode) + "/threads", threads);
  const long hits = std::count(call.response.hit.begin(), call.response.hit.end(), true);
  std::printf(
      "ray_cast through the node, C++ client: %d rays, %ld hits, ~threads %d; best of %d "
      "round trips %.1f ms; this client serialises %.1f ms and deserialises %.1f ms; the "
      "node and the transport %.1f ms\n",
      ray_count, hits, threads, calls, 1e3 * best, 1e3 * encode, 1e3 * decode,
      1e3 * (best - encode - decode));
  return Check(scene, call.response, checked) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "ray_service_client", ros::init_options::AnonymousName);
  const int rays = argc > 1 ? std::max(1, std::atoi(argv[1])) : 100000;
  const int calls = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  const int checked = argc > 3 ? std::max(0, std::atoi(argv[3])) : 1000;
  ros::NodeHandle node;
  return Run(node, rays, calls, checked);
}
