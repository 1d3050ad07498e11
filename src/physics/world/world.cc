// World forwards to WorldImpl, which holds the stages' state. The calls
// that may change the pairs or the bodies' slots that the last step's
// contact reports are made of write those reports first
// (WorldImpl::FlushReports): a report is written when it is first read.
#include "rigid_body_sim/physics/world.h"

#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

World::World(const WorldSettings& settings) : impl_(std::make_unique<WorldImpl>(settings)) {}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

const WorldSettings& World::settings() const { return impl_->settings(); }
Status World::SetSettings(const WorldSettings& settings) {
  impl_->FlushReports();
  return impl_->SetSettings(settings);
}

Result<BodyId> World::CreateBody(const BodyDef& def) {
  impl_->FlushReports();
  return impl_->CreateBody(def);
}
Status World::DestroyBody(BodyId id) {
  impl_->FlushReports();
  return impl_->DestroyBody(id);
}
bool World::IsValid(BodyId id) const { return impl_->IsValid(id); }
std::size_t World::BodyCount() const { return impl_->BodyCount(); }
std::size_t World::AwakeBodyCount() const { return impl_->AwakeBodyCount(); }

Pose World::GetPose(BodyId id) const { return impl_->GetPose(id); }
Vec3 World::GetLinearVelocity(BodyId id) const { return impl_->GetLinearVelocity(id); }
Vec3 World::GetAngularVelocity(BodyId id) const { return impl_->GetAngularVelocity(id); }
Status World::SetState(BodyId id, const Pose& world_from_body, const Vec3& linear_velocity,
                       const Vec3& angular_velocity) {
  impl_->FlushReports();
  return impl_->SetState(id, world_from_body, linear_velocity, angular_velocity);
}
const Body& World::GetBody(BodyId id) const { return impl_->GetBody(id); }

Status World::ApplyForceAtPoint(BodyId id, const Vec3& force_world, const Vec3& point_world) {
  return impl_->ApplyForceAtPoint(id, force_world, point_world);
}
Status World::ApplyTorque(BodyId id, const Vec3& torque_world) {
  return impl_->ApplyTorque(id, torque_world);
}

void World::Step() { impl_->Step(); }
std::vector<BodyOverlap> World::FindOverlaps(BodyId id) const { return impl_->FindOverlaps(id); }
Result<std::vector<RayHit>> World::CastRays(const std::vector<Ray>& rays,
                                            const std::vector<BodyId>& ignore) const {
  return impl_->CastRays(rays, ignore);
}
double World::time() const { return impl_->time(); }
const StepProfile& World::last_step_profile() const { return impl_->last_step_profile(); }
void World::Restart() { impl_->Restart(); }
const std::vector<BodyId>& World::non_finite_bodies() const { return impl_->non_finite_bodies(); }
const std::vector<ContactReport>& World::contacts() const { return impl_->contacts(); }
std::vector<ContactReport> World::TakeCollisionLog() { return impl_->TakeCollisionLog(); }

Result<ArticulationId> World::CreateArticulation(const ArticulationDef& def) {
  impl_->FlushReports();
  return impl_->CreateArticulation(def);
}
Status World::DestroyArticulation(ArticulationId id) {
  impl_->FlushReports();
  return impl_->DestroyArticulation(id);
}
bool World::IsValid(ArticulationId id) const { return impl_->IsValid(id); }
std::vector<BodyId> World::ArticulationLinks(ArticulationId id) const {
  return impl_->ArticulationLinks(id);
}
std::vector<JointState> World::GetJointStates(ArticulationId id) const {
  return impl_->GetJointStates(id);
}
Status World::SetJointStates(ArticulationId id, const std::vector<double>& positions,
                             const std::vector<double>& velocities) {
  impl_->FlushReports();
  return impl_->SetJointStates(id, positions, velocities);
}
Status World::SetJointCommand(ArticulationId id, int joint, const JointCommand& command) {
  return impl_->SetJointCommand(id, joint, command);
}
Status World::SetServoGains(ArticulationId id, const ServoGains& gains) {
  return impl_->SetServoGains(id, gains);
}

}  // namespace rigid_body_sim::physics
