#include "physics/world/world_impl.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <variant>

#include "physics/collision/mesh_collision.h"
#include "physics/dynamics/body_state.h"
#include "physics/geometry/shape_bounds.h"

namespace rigid_body_sim::physics {
namespace {

// Limits of the contact cache's keys.
constexpr std::size_t kMaxShapesPerBody = 4096;
constexpr std::size_t kMaxBodies = std::size_t{1} << 20;

}  // namespace

namespace {

// A pool of the threads `settings` ask for; out-of-range counts (refused by
// ValidateWorldSettings, reaching here only with asserts off) clamp.
std::unique_ptr<TaskPool> MakePool(const WorldSettings& settings) {
  return std::make_unique<TaskPool>(
      std::clamp(ResolveThreadCount(settings.threads), 1, kMaxThreads));
}

}  // namespace

WorldImpl::WorldImpl(const WorldSettings& settings)
    : settings_(settings),
      pool_(MakePool(settings)),
      motion_solver_(MakeMotionSolver(settings.motion_solver, this)) {
  assert(ValidateWorldSettings(settings).ok());
  solver_.set_pool(pool_.get());
}

Status WorldImpl::SetSettings(const WorldSettings& settings) {
  Status status = ValidateWorldSettings(settings);
  if (!status.ok()) return status;
  if (ResolveThreadCount(settings.threads) != pool_->threads()) {
    pool_ = MakePool(settings);
    solver_.set_pool(pool_.get());
  }
  if (settings.motion_solver != settings_.motion_solver) {
    motion_solver_ = MakeMotionSolver(settings.motion_solver, this);
  }
  settings_ = settings;
  return status;
}

namespace {

// A body definition's pose, velocities and shapes, checked before any of it
// enters the world.
Status ValidateBodyDef(const BodyDef& def) {
  if (Status status = ValidateState(def.world_from_body, def.linear_velocity, def.angular_velocity);
      !status.ok()) {
    return status;
  }
  for (std::size_t i = 0; i < def.shapes.size(); ++i) {
    const ShapeDef& shape = def.shapes[i];
    if (Status status = ValidateShapeDef(shape); !status.ok()) {
      return Status::Error("shape " + std::to_string(i) + ": " + status.message());
    }
    if (std::holds_alternative<HalfSpace>(shape.geometry) &&
        (!def.is_static || def.shapes.size() != 1)) {
      return Status::Error("shape " + std::to_string(i) +
                           ": a half-space must be the only shape of a static body");
    }
    if (std::holds_alternative<StaticMesh>(shape.geometry) && !def.is_static) {
      return Status::Error("shape " + std::to_string(i) +
                           ": a static triangle mesh needs a static body (is_static); a moving "
                           "body's mesh must be a convex hull or convex pieces");
    }
  }
  if (def.shapes.size() > kMaxShapesPerBody) {
    return Status::Error("a body may have at most " + std::to_string(kMaxShapesPerBody) +
                         " shapes, got " + std::to_string(def.shapes.size()));
  }
  return Status::Ok();
}

}  // namespace

Result<BodyId> WorldImpl::CreateBody(const BodyDef& def) {
  if (Status status = ValidateBodyDef(def); !status.ok()) return status;
  if (body_count_ >= kMaxBodies) {
    return Status::Error("the world is full: " + std::to_string(kMaxBodies) + " bodies");
  }

  Body body;
  body.is_static = def.is_static;
  body.user_data = def.user_data;
  body.shapes = def.shapes;
  AddMeshSlots(&body.shapes);
  if (body.shapes.size() > kMaxShapesPerBody) {
    return Status::Error("a body may have at most " + std::to_string(kMaxShapesPerBody) +
                         " shapes, counting " + std::to_string(StaticMesh::kContactSlots) +
                         " per static mesh, got " + std::to_string(body.shapes.size()));
  }
  if (!def.is_static) {
    if (Status status = ValidateMassProperties(def.mass_properties); !status.ok()) {
      return status;
    }
    const PrincipalAxes axes = ComputePrincipalAxes(def.mass_properties.inertia_about_com);
    body.mass = def.mass_properties.mass;
    body.inverse_mass = 1.0 / body.mass;
    body.inverse_principal_moments = axes.principal_moments.cwiseInverse();
    const Pose body_from_principal{def.mass_properties.center_of_mass, axes.body_from_principal};
    body.principal_from_body = body_from_principal.Inverse();
  }
  SetBodyState(def.world_from_body, def.linear_velocity, def.angular_velocity, &body);
  body.in_use = true;
  body.thickness = std::numeric_limits<double>::infinity();
  const Vec3 com_body = body.principal_from_body.Inverse().translation;
  for (const ShapeDef& shape : body.shapes) {
    // A half-space is unbounded; it is static, so its size never limits motion.
    if (std::holds_alternative<HalfSpace>(shape.geometry)) continue;
    body.thickness = std::min(body.thickness, ShapeThickness(shape.geometry));
    body.bounding_radius =
        std::max(body.bounding_radius,
                 ShapeBoundingRadius(shape.geometry, shape.body_from_shape.Inverse() * com_body));
  }

  BodyId id;
  if (free_slots_.empty()) {
    id.index = static_cast<std::uint32_t>(bodies_.size());
    bodies_.push_back(std::move(body));
  } else {
    id.index = free_slots_.back();
    free_slots_.pop_back();
    body.generation = bodies_[id.index].generation;
    bodies_[id.index] = std::move(body);
  }
  id.generation = bodies_[id.index].generation;
  ++body_count_;
  sleep_.RestartWindow(id.index);
  collision_.AddBody(id.index);
  return id;
}

BodyId WorldImpl::BodyIdOf(std::uint32_t index) const {
  return BodyId{index, bodies_[index].generation};
}

void WorldImpl::RestartContacts(std::uint32_t body) {
  WakeTouching(body);
  contact_cache_.RemoveBody(body);
}

Status WorldImpl::DestroyBody(BodyId id) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  Body& body = bodies_[id.index];
  if (body.articulation >= 0) {
    return Status::Error("the body is a link of an articulation; destroy the articulation");
  }
  collision_.ForgetBody(id.index);
  contact_cache_.RemoveBody(id.index);
  WakeTouching(id.index);
  const std::uint32_t next_generation = body.generation + 1;
  body = Body();
  body.generation = next_generation;
  free_slots_.push_back(id.index);
  --body_count_;
  return Status::Ok();
}

bool WorldImpl::IsValid(BodyId id) const {
  return id.index < bodies_.size() && bodies_[id.index].in_use &&
         bodies_[id.index].generation == id.generation;
}

const Body& WorldImpl::GetBody(BodyId id) const {
  assert(IsValid(id));
  return bodies_[id.index];
}

Body& WorldImpl::MutableBody(BodyId id) {
  assert(IsValid(id));
  return bodies_[id.index];
}

Pose WorldImpl::GetPose(BodyId id) const { return GetBody(id).WorldFromBody(); }

Vec3 WorldImpl::GetLinearVelocity(BodyId id) const {
  const Body& body = GetBody(id);
  return body.PointVelocity(body.WorldFromBody().translation);
}

Vec3 WorldImpl::GetAngularVelocity(BodyId id) const { return GetBody(id).angular_velocity; }

Status WorldImpl::SetState(BodyId id, const Pose& world_from_body, const Vec3& linear_velocity,
                           const Vec3& angular_velocity) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (Status status = ValidateState(world_from_body, linear_velocity, angular_velocity);
      !status.ok()) {
    return status;
  }
  Body& body = MutableBody(id);
  if (body.articulation >= 0) {
    return articulations_.MoveWithLink(static_cast<std::uint32_t>(body.articulation),
                                       world_from_body, linear_velocity, angular_velocity,
                                       body.link);
  }
  body.disabled = false;
  SetBodyState(world_from_body, linear_velocity, angular_velocity, &body);
  sleep_.RestartWindow(id.index);
  // Teleported: last step's contacts and impulses no longer apply, and
  // whatever rested on the body must notice that it left.
  WakeTouching(id.index);
  contact_cache_.RemoveBody(id.index);
  if (body.is_static) collision_.RemoveProxy(id.index);
  return Status::Ok();
}

Status WorldImpl::ApplyForceAtPoint(BodyId id, const Vec3& force_world, const Vec3& point_world) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (!IsFinite(force_world))
    return Status::Error("force is not finite: " + FormatVector(force_world));
  if (!IsFinite(point_world))
    return Status::Error("point is not finite: " + FormatVector(point_world));
  Body& body = MutableBody(id);
  if (body.is_static) return Status::Ok();
  Wake(id.index);
  body.force += force_world;
  body.torque += (point_world - body.position).cross(force_world);
  return Status::Ok();
}

Status WorldImpl::ApplyTorque(BodyId id, const Vec3& torque_world) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (!IsFinite(torque_world)) {
    return Status::Error("torque is not finite: " + FormatVector(torque_world));
  }
  Body& body = MutableBody(id);
  if (body.is_static) return Status::Ok();
  Wake(id.index);
  body.torque += torque_world;
  return Status::Ok();
}

void WorldImpl::Restart() {
  time_ = 0.0;
  reports_.Clear();
  contact_cache_.Clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].in_use && !bodies_[i].is_static) Wake(i);
  }
}

std::size_t WorldImpl::AwakeBodyCount() const {
  std::size_t count = 0;
  for (const Body& body : bodies_) count += body.in_use && !body.is_static && body.awake;
  return count;
}

void WorldImpl::Wake(std::uint32_t index) {
  Body& body = bodies_[index];
  if (body.disabled) return;
  woke_since_prune_ |= !body.awake;
  body.awake = true;
  body.sleep_time = 0.0;
  body.speeding_up_time = 0.0;
  sleep_.RestartWindow(index);
}

void WorldImpl::WakeTouching(std::uint32_t index) {
  for (const ContactReport& contact : reports_.contacts(pool_.get())) {
    if (contact.body_a.index != index && contact.body_b.index != index) continue;
    for (const BodyId other : {contact.body_a, contact.body_b}) {
      if (other.index != index && IsValid(other) && !bodies_[other.index].is_static) {
        Wake(other.index);
      }
    }
  }
}

void WorldImpl::Step() {
  const StepContext step(settings_, pool_.get());
  non_finite_bodies_.clear();
  // The last step's reports that nobody read are never written: this
  // step's take their place.
  reports_.DiscardPending();
  // Wall time since the previous lap, ms; steady_clock costs tens of
  // nanoseconds a read, nothing next to a stage.
  std::chrono::steady_clock::time_point lap_start = std::chrono::steady_clock::now();
  auto lap = [&lap_start]() {
    const std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - lap_start).count();
    lap_start = now;
    return ms;
  };
  StepProfile& profile = last_step_profile_;

  GuardBeforeStep(step);
  collision_.UpdateBroadPhase(step);
  profile.broad_phase_ms = lap();
  collision_.UpdateNarrowPhase(step);
  profile.reused_manifolds = collision_.reused_manifolds();
  profile.narrow_phase_ms = lap();
  UpdateContactCache();
  profile.contact_cache_ms = lap();
  motion_solver_->Solve(step);
  profile.solver_ms = lap();
  motion_solver_->Integrate(step);
  profile.integrator_ms = lap();
  GuardAfterStep();

  profile.solver_points = 0;
  for (const SolverManifold& manifold : solver_.manifolds()) {
    profile.solver_points += static_cast<std::size_t>(manifold.point_count);
  }
  profile.velocity_sweeps = solver_.velocity_sweeps();
  profile.velocity_row_updates = solver_.velocity_row_updates();
  profile.island_groups = solver_.island_groups();
  time_ += step.dt;
}

// The bodies that move this step; the stages from here on visit only them,
// so sleeping bodies cost nothing.
void WorldImpl::ListMovingBodies() {
  moving_bodies_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (MovesThisStep(bodies_[i])) moving_bodies_.push_back(i);
  }
}

}  // namespace rigid_body_sim::physics
