// ~ray_cast: rays in a frame of the request, cast against the world's
// shapes (physics::World::CastRays), answered in the same frame.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "node/service_reply.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Pose;
using physics::Result;
using physics::Status;

namespace {

// Each shape's frame name is looked up once per request: most of a large
// batch hits a few shapes (a laser's room, a terrain). A hit on the shape
// of the hit before it (most of them, on a terrain) takes the name from
// there without the table.
void FillHitFrames(const std::vector<physics::RayHit>& hits, const ModelRegistry& registry,
                   const std::optional<physics::BodyId>& ground,
                   std::vector<std::string>* hit_frames) {
  std::unordered_map<std::uint64_t, std::string> frames;
  hit_frames->resize(hits.size());
  std::uint64_t last_key = 0;
  const std::string* last = nullptr;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].hit) continue;
    const std::uint64_t key =
        std::uint64_t{hits[i].body.index} << 32 | static_cast<std::uint32_t>(hits[i].shape);
    if (last == nullptr || key != last_key) {
      auto [frame, added] = frames.try_emplace(key);
      if (added) {
        frame->second = ground && hits[i].body == *ground
                            ? std::string(names::kGroundName)
                            : registry.ShapeFrame(hits[i].body, hits[i].shape);
      }
      last_key = key;
      last = &frame->second;
    }
    (*hit_frames)[i] = *last;
  }
}

}  // namespace

bool SimNode::OnRayCast(rigid_body_sim::RayCast::Request& request,
                        rigid_body_sim::RayCast::Response& response) {
  // Parsed and checked whole before the world is locked.
  Result<std::vector<physics::Ray>> rays =
      RaysFromMsg(request.origins, request.directions, request.max_distance);
  if (!rays.ok()) return Fail(response, rays.message(), names::kRayCastService);
  std::vector<physics::Ray> world_rays = std::move(rays).value();
  std::vector<physics::RayHit> hits;
  Pose world_from_frame = Pose::Identity();
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    if (!request.frame_id.empty()) {
      Result<FrameRef> frame = registry_.ResolveFrame(request.frame_id);
      if (!frame.ok())
        return Fail(response, "frame_id: " + frame.message(), names::kRayCastService);
      world_from_frame =
          LinkStateLocked(*frame->model,
                          static_cast<std::size_t>(frame->link - frame->model->links.data()))
              .world_from_frame;
    }
    std::vector<physics::BodyId> ignore;
    for (std::size_t i = 0; i < request.ignore_models.size(); ++i) {
      const Model* model = registry_.Find(request.ignore_models[i]);
      if (model == nullptr) {
        return Fail(response,
                    "ignore_models[" + std::to_string(i) + "]: no model named '" +
                        request.ignore_models[i] + "'",
                    names::kRayCastService);
      }
      ignore.insert(ignore.end(), model->bodies.begin(), model->bodies.end());
    }
    // Rays in the world frame are cast as they came, not turned by the
    // identity.
    if (!request.frame_id.empty()) {
      for (physics::Ray& ray : world_rays) {
        ray.origin = world_from_frame * ray.origin;
        ray.direction = world_from_frame.rotation * ray.direction;
      }
    }
    Result<std::vector<physics::RayHit>> cast = world_.CastRays(world_rays, ignore);
    if (!cast.ok()) return Fail(response, cast.message(), names::kRayCastService);
    hits = std::move(cast).value();
    FillHitFrames(hits, registry_, ground_, &response.hit_frames);
  }
  const Pose frame_from_world = world_from_frame.Inverse();
  response.hit.resize(hits.size());
  response.distance.resize(hits.size());
  response.points.resize(hits.size());
  response.normals.resize(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) {
    response.hit[i] = hits[i].hit;
    response.distance[i] = hits[i].distance;
    if (!hits[i].hit) continue;
    if (request.frame_id.empty()) {
      response.points[i] = PointToMsg(hits[i].point);
      response.normals[i] = VectorToMsg(hits[i].normal);
    } else {
      response.points[i] = PointToMsg(frame_from_world * hits[i].point);
      response.normals[i] = VectorToMsg(frame_from_world.rotation * hits[i].normal);
    }
  }
  response.success = true;
  return true;
}

}  // namespace rigid_body_sim::node
