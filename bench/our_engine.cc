// The scenes in rigid_body_sim::physics::World with its default settings,
// or with the few that OurSettingsOverrides sets.
#include <algorithm>
#include <cassert>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::bench {
namespace {

namespace physics = rigid_body_sim::physics;

physics::Material ToMaterial(const BenchMaterial& material) {
  physics::Material result;
  result.friction = material.friction;
  result.restitution = material.restitution;
  return result;
}

// Boxes of one size share one polyhedron, as a user's meshes would.
class BoxPolyhedra {
 public:
  std::shared_ptr<const physics::ConvexPolyhedron> Get(const Vec3& size) {
    auto found = std::find_if(polyhedra_.begin(), polyhedra_.end(),
                              [&](const auto& entry) { return entry.first == size; });
    if (found != polyhedra_.end()) return found->second;
    polyhedra_.emplace_back(
        size, std::make_shared<const physics::ConvexPolyhedron>(physics::MakeBoxPolyhedron(size)));
    return polyhedra_.back().second;
  }

 private:
  std::vector<std::pair<Vec3, std::shared_ptr<const physics::ConvexPolyhedron>>> polyhedra_;
};

physics::LinkDef ToLinkDef(const BenchLink& link, BoxPolyhedra* polyhedra) {
  physics::LinkDef def;
  def.mass_properties.mass = link.mass;
  def.mass_properties.center_of_mass = link.center_of_mass;
  def.mass_properties.inertia_about_com = link.inertia_diagonal.asDiagonal();
  if (link.has_box) {
    physics::ShapeDef shape;
    shape.geometry = polyhedra->Get(link.box_size);
    shape.body_from_shape.translation = link.center_of_mass;
    shape.material = ToMaterial(link.material);
    def.shapes.push_back(shape);
  }
  return def;
}

physics::ArticulationDef ToArticulationDef(const BenchArticulation& articulation,
                                           BoxPolyhedra* polyhedra) {
  physics::ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base = articulation.world_from_base;
  for (const BenchLink& link : articulation.links) {
    def.links.push_back(ToLinkDef(link, polyhedra));
  }
  for (std::size_t j = 0; j < articulation.joints.size(); ++j) {
    const BenchJoint& joint = articulation.joints[j];
    physics::JointDef joint_def;
    joint_def.name = "joint_" + std::to_string(j);
    joint_def.type = physics::JointType::kContinuous;
    joint_def.parent_link = joint.parent;
    joint_def.child_link = static_cast<int>(j) + 1;
    joint_def.parent_from_joint.translation = joint.parent_offset;
    joint_def.axis = joint.axis;
    joint_def.position = joint.position;
    joint_def.effort_limit = joint.effort_limit;
    def.joints.push_back(joint_def);
  }
  return def;
}

// A joint of the scene, numbered over all its articulations.
struct OurJoint {
  physics::ArticulationId articulation;
  int index = 0;  // within its articulation
  physics::BodyId parent;
  physics::BodyId child;
  Vec3 parent_offset;  // m, parent link frame: the anchor
};

class OurEngine : public Engine {
 public:
  OurEngine(const Scene& scene, const OurSettingsOverrides& overrides) {
    physics::WorldSettings settings;
    settings.time_step = scene.time_step;
    physics::SolverSettings& solver = settings.solver;
    solver.velocity_iterations = overrides.velocity_iterations.value_or(solver.velocity_iterations);
    solver.velocity_tolerance = overrides.velocity_tolerance.value_or(solver.velocity_tolerance);
    solver.interleave_independent_runs =
        overrides.interleave_independent_runs.value_or(solver.interleave_independent_runs);
    solver.batch_independent_runs =
        overrides.batch_independent_runs.value_or(solver.batch_independent_runs);
    settings.soft_step.simd_lanes =
        overrides.soft_simd_lanes.value_or(settings.soft_step.simd_lanes);
    settings.sleep.time_to_sleep = overrides.time_to_sleep.value_or(settings.sleep.time_to_sleep);
    settings.threads = overrides.threads.value_or(settings.threads);
    settings.motion_solver = overrides.motion_solver.value_or(settings.motion_solver);
    assert(physics::ValidateWorldSettings(settings).ok());
    world_ = std::make_unique<physics::World>(settings);

    physics::BodyDef ground;
    ground.is_static = true;
    ground.world_from_body = scene.world_from_ground;
    physics::ShapeDef half_space;
    half_space.geometry = physics::HalfSpace{};
    if (!scene.terrain.triangles.empty()) {
      ground.world_from_body = Pose::Identity();
      half_space.geometry =
          physics::StaticMesh{physics::CollisionMesh::Make(scene.terrain).value()};
    }
    half_space.material = ToMaterial(scene.ground_material);
    ground.shapes.push_back(half_space);
    world_->CreateBody(ground).value();

    BoxPolyhedra polyhedra;
    for (const BenchBody& body : scene.bodies) {
      physics::BodyDef def;
      def.world_from_body = body.world_from_body;
      physics::ShapeDef shape;
      shape.material = ToMaterial(body.material);
      if (body.shape == BenchBody::Shape::kBox) {
        shape.geometry = polyhedra.Get(body.box_size);
        def.mass_properties =
            physics::BoxMassProperties(body.mass / body.box_size.prod(), body.box_size);
      } else {
        const double r = body.sphere_radius;
        shape.geometry = physics::Sphere{r};
        def.mass_properties =
            physics::SphereMassProperties(body.mass / (4.0 / 3.0 * M_PI * r * r * r), r);
      }
      def.shapes.push_back(shape);
      ids_.push_back(world_->CreateBody(def).value());
    }
    moving_ = ids_;
    for (const BenchArticulation& articulation : scene.articulations) {
      const physics::ArticulationId id =
          world_->CreateArticulation(ToArticulationDef(articulation, &polyhedra)).value();
      const std::vector<physics::BodyId> links = world_->ArticulationLinks(id);
      moving_.insert(moving_.end(), links.begin() + 1, links.end());  // the base is fixed
      for (std::size_t j = 0; j < articulation.joints.size(); ++j) {
        const BenchJoint& joint = articulation.joints[j];
        joints_.push_back(OurJoint{id, static_cast<int>(j), links[joint.parent], links[j + 1],
                                   joint.parent_offset});
      }
    }
  }

  std::string name() const override { return "ours"; }
  void Step() override { world_->Step(); }

  StageTimes LastStageTimes() const override {
    const physics::StepProfile& profile = world_->last_step_profile();
    StageTimes times;
    times.broad_phase_ms = profile.broad_phase_ms;
    times.narrow_phase_ms = profile.narrow_phase_ms + profile.contact_cache_ms;
    times.solver_ms = profile.solver_ms;
    times.integrator_ms = profile.integrator_ms;
    times.solver_points = profile.solver_points;
    times.point_iterations = profile.velocity_row_updates;
    return times;
  }

  Vec3 Position(int index) const override { return world_->GetPose(ids_[index]).translation; }
  Vec3 LinearVelocity(int index) const override { return world_->GetLinearVelocity(ids_[index]); }

  // T = 1/2 v.P + 1/2 omega.L per body.
  double KineticEnergy() const override {
    double energy = 0.0;
    for (const physics::BodyId id : ids_) {
      const physics::Body& body = world_->GetBody(id);
      energy += 0.5 * body.linear_velocity.dot(body.linear_momentum) +
                0.5 * body.angular_velocity.dot(body.angular_momentum);
    }
    return energy;
  }

  double MechanicalEnergy() const override {
    double energy = 0.0;
    for (const physics::BodyId id : moving_) {
      const physics::Body& body = world_->GetBody(id);
      energy += 0.5 * body.linear_velocity.dot(body.linear_momentum) +
                0.5 * body.angular_velocity.dot(body.angular_momentum) +
                body.mass * kGravity * body.position.z();
    }
    return energy;
  }

  double MaxPenetration() const override {
    double depth = 0.0;
    for (const physics::ContactReport& contact : world_->contacts()) {
      depth = std::max(depth, contact.depth);
    }
    return depth;
  }

  // A normal row and a two-dimensional friction row (the Coulomb disc).
  int RowsPerPoint() const override { return 3; }

  bool AllMovingBodiesAwake() const override {
    return std::all_of(moving_.begin(), moving_.end(),
                       [&](physics::BodyId id) { return world_->GetBody(id).awake; });
  }

  // The child link frame's origin is the joint's anchor (JointDef).
  double JointAnchorSeparation() const override {
    double separation = 0.0;
    for (const OurJoint& joint : joints_) {
      const Vec3 on_parent = world_->GetPose(joint.parent) * joint.parent_offset;
      separation =
          std::max(separation, (on_parent - world_->GetPose(joint.child).translation).norm());
    }
    return separation;
  }

  double JointPosition(int joint) const override {
    const OurJoint& our_joint = joints_[joint];
    return world_->GetJointStates(our_joint.articulation)[our_joint.index].position;
  }

  void SetMotorVelocity(int joint, double velocity) override {
    physics::JointCommand command;
    command.mode = physics::JointCommandMode::kVelocity;
    command.velocity = velocity;
    const OurJoint& our_joint = joints_[joint];
    const physics::Status status =
        world_->SetJointCommand(our_joint.articulation, our_joint.index, command);
    assert(status.ok());
    (void)status;
  }

 private:
  std::unique_ptr<physics::World> world_;
  std::vector<physics::BodyId> ids_;     // the scene's free bodies, in order
  std::vector<physics::BodyId> moving_;  // those and every link but a fixed base
  std::vector<OurJoint> joints_;
};

}  // namespace

std::unique_ptr<Engine> MakeOurEngine(const Scene& scene, const OurSettingsOverrides& overrides) {
  return std::make_unique<OurEngine>(scene, overrides);
}

}  // namespace rigid_body_sim::bench
