// The scenes in rigid_body_sim::physics::World with its default settings,
// or with the few that OurSettingsOverrides sets.
#include <algorithm>
#include <cassert>
#include <memory>
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

class OurEngine : public Engine {
 public:
  OurEngine(const Scene& scene, const OurSettingsOverrides& overrides) {
    physics::WorldSettings settings;
    settings.time_step = kTimeStep;
    physics::SolverSettings& solver = settings.solver;
    solver.velocity_iterations = overrides.velocity_iterations.value_or(solver.velocity_iterations);
    solver.velocity_tolerance = overrides.velocity_tolerance.value_or(solver.velocity_tolerance);
    solver.interleave_independent_runs =
        overrides.interleave_independent_runs.value_or(solver.interleave_independent_runs);
    settings.sleep.time_to_sleep = overrides.time_to_sleep.value_or(settings.sleep.time_to_sleep);
    assert(physics::ValidateWorldSettings(settings).ok());
    world_ = std::make_unique<physics::World>(settings);

    physics::BodyDef ground;
    ground.is_static = true;
    ground.world_from_body = scene.world_from_ground;
    physics::ShapeDef ground_shape;
    ground_shape.material = ToMaterial(scene.ground_material);
    if (scene.terrain.triangles.empty()) {
      ground_shape.geometry = physics::HalfSpace{};
    } else {
      ground.world_from_body = Pose::Identity();
      ground_shape.geometry =
          physics::StaticMesh{physics::CollisionMesh::Make(scene.terrain).value()};
    }
    ground.shapes.push_back(ground_shape);
    world_->CreateBody(ground).value();

    // Boxes of one size share one polyhedron, as a user's meshes would.
    std::vector<std::pair<Vec3, std::shared_ptr<const physics::ConvexPolyhedron>>> polyhedra;
    for (const BenchBody& body : scene.bodies) {
      physics::BodyDef def;
      def.world_from_body = body.world_from_body;
      physics::ShapeDef shape;
      shape.material = ToMaterial(body.material);
      if (body.shape == BenchBody::Shape::kBox) {
        auto found = std::find_if(polyhedra.begin(), polyhedra.end(),
                                  [&](const auto& entry) { return entry.first == body.box_size; });
        if (found == polyhedra.end()) {
          polyhedra.emplace_back(body.box_size, std::make_shared<const physics::ConvexPolyhedron>(
                                                    physics::MakeBoxPolyhedron(body.box_size)));
          found = polyhedra.end() - 1;
        }
        shape.geometry = found->second;
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

  double MaxPenetration() const override {
    double depth = 0.0;
    for (const physics::ContactReport& contact : world_->contacts()) {
      depth = std::max(depth, contact.depth);
    }
    return depth;
  }

  // A normal row and a two-dimensional friction row (the Coulomb disc).
  int RowsPerPoint() const override { return 3; }

 private:
  std::unique_ptr<physics::World> world_;
  std::vector<physics::BodyId> ids_;
};

}  // namespace

std::unique_ptr<Engine> MakeOurEngine(const Scene& scene, const OurSettingsOverrides& overrides) {
  return std::make_unique<OurEngine>(scene, overrides);
}

}  // namespace rigid_body_sim::bench
