// Face manifolds carried with the bodies (WorldSettings::contact_reuse_distance)
// against manifolds clipped every step and against analytic answers.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::Translation;

constexpr double kG = 9.81;

WorldSettings Settings(double reuse_distance) {
  WorldSettings settings;
  settings.contact_reuse_distance = reuse_distance;
  settings.sleep.enabled = false;  // the narrow phase and solver run every step
  return settings;
}

// Expects each of `reports` to match the nearest of `reference` between the
// same bodies in depth (within `depth_tolerance`) and normal, no more than
// `max_lag` away; raises `largest_lag` to the largest distance of a match.
void ExpectMatch(const std::vector<ContactReport>& reports,
                 const std::vector<ContactReport>& reference, double depth_tolerance,
                 double max_lag, double* largest_lag) {
  ASSERT_EQ(reports.size(), reference.size());
  for (const ContactReport& report : reports) {
    const ContactReport* nearest = nullptr;
    double lag = std::numeric_limits<double>::infinity();
    for (const ContactReport& other : reference) {
      const double distance = (other.position_world - report.position_world).norm();
      if (other.body_a == report.body_a && other.body_b == report.body_b && distance < lag) {
        lag = distance;
        nearest = &other;
      }
    }
    ASSERT_NE(nearest, nullptr) << "no reference report between the same bodies";
    EXPECT_NEAR(report.depth, nearest->depth, depth_tolerance);
    EXPECT_LT((report.normal_world - nearest->normal_world).norm(), 1e-12);
    EXPECT_LT(lag, max_lag);
    *largest_lag = std::max(*largest_lag, lag);
  }
}

// Summed normal force (N) that `below` exerts upwards on `above`.
double UpwardForce(const World& world, BodyId above, BodyId below) {
  double force = 0.0;
  for (const ContactReport& contact : world.contacts()) {
    const double up = contact.normal_force * contact.normal_world.z();  // on body A
    if (contact.body_a == above && contact.body_b == below) force += up;
    if (contact.body_a == below && contact.body_b == above) force -= up;
  }
  return force;
}

BoxSpec StaticBox(const Vec3& size, const Pose& world_from_body, double friction) {
  BoxSpec spec;
  spec.size = size;
  spec.is_static = true;
  spec.world_from_body = world_from_body;
  spec.material = MakeMaterial(friction, 0.0);
  return spec;
}

struct Stack {
  BodyId ground;
  std::vector<BodyId> boxes;  // bottom up
};

// The ground and `count` unit boxes of 1 kg (mu 0.5) stacked on it, each
// sunk by `overlap` (m) into the one below.
Stack AddStack(World* world, int count, double overlap) {
  Stack stack;
  stack.ground = AddGround(world, MakeMaterial(0.5, 0.0));
  for (int i = 0; i < count; ++i) {
    BoxSpec spec;
    spec.world_from_body = Translation(0, 0, 0.5 + i * (1.0 - overlap));
    spec.material = MakeMaterial(0.5, 0.0);
    stack.boxes.push_back(AddBox(world, spec));
  }
  return stack;
}

// A resting five-box stack, reuse on and off: each contact carries the
// weight above it, the stack sinks by at most the slop per contact, and at
// every step the reused box-box reports match a fresh clip of the same poses.
TEST(ManifoldReuseTest, RestingStackMatchesClippingEveryStep) {
  const int count = 5;
  World reused(Settings(1e-3));
  World clipped(Settings(0.0));
  const double overlap = 5e-5;  // m, within the slop; the first clip sees it
  const Stack stack = AddStack(&reused, count, overlap);
  AddStack(&clipped, count, overlap);  // the same ids
  const SolverSettings& solver = reused.settings().solver;
  double largest_lag = 0.0;          // m, of a reused point behind the clipped one
  std::size_t reused_manifolds = 0;  // carried by `reused`, over the run
  for (int step = 0; step < 240 * 2; ++step) {
    // A world that clips the poses `reused` starts this step from.
    World fresh(Settings(0.0));
    AddStack(&fresh, count, overlap);
    for (const BodyId box : stack.boxes) {
      const Status set = fresh.SetState(box, reused.GetPose(box), reused.GetLinearVelocity(box),
                                        reused.GetAngularVelocity(box));
      ASSERT_TRUE(set.ok()) << set.message();
    }
    reused.Step();
    clipped.Step();
    fresh.Step();
    reused_manifolds += reused.last_step_profile().reused_manifolds;
    ASSERT_EQ(clipped.last_step_profile().reused_manifolds, 0u);
    SCOPED_TRACE(::testing::Message() << "step " << step);
    std::vector<ContactReport> box_box[2];
    for (int w = 0; w < 2; ++w) {
      for (const ContactReport& contact : (w == 0 ? reused : fresh).contacts()) {
        if (contact.body_b != stack.ground) box_box[w].push_back(contact);
      }
    }
    // Vertex-face gaps are exact; clipping an incident edge instead of
    // keeping its vertex changes a gap by tilt (< 1e-4) x lag (< 1e-4 m).
    ExpectMatch(box_box[0], box_box[1], 1e-8, reused.settings().contact_reuse_distance,
                &largest_lag);
    if (step < 60) continue;  // 0.25 s for PGS to settle from a cold start
    for (World* world : {&reused, &clipped}) {
      for (int i = 0; i < count; ++i) {
        const BodyId below = i == 0 ? stack.ground : stack.boxes[i - 1];
        const double weight = (count - i) * 1.0 * kG;  // N, of the boxes from i up
        EXPECT_NEAR(UpwardForce(*world, stack.boxes[i], below) / weight, 1.0, 0.01)
            << (world == &reused ? "reused" : "clipped") << ", box " << i;
      }
      const double top = world->GetPose(stack.boxes.back()).translation.z();
      EXPECT_GT(top, count - 0.5 - count * solver.penetration_slop);  // <= slop each
      EXPECT_LT(top, count - 0.5 + count * solver.contact_tolerance);
    }
  }
  // Every step after the first carries the four box-box manifolds; a stack
  // that holds perfectly still gives lags of zero, which the matches allow.
  EXPECT_EQ(reused_manifolds, static_cast<std::size_t>(240 * 2 - 1) * (count - 1))
      << "largest lag " << largest_lag << " m";
}

// A box drifting and spinning slowly off a tilted static box, no gravity or
// friction: its parallel face keeps an exact gap d(t) = d0 - v_n t at every
// reused point, and the points keep up with it.
TEST(ManifoldReuseTest, ReusedGapsOfADriftingBoxAreExact) {
  const double d0 = 5e-3;    // m, initial overlap along the face normal
  const double v_n = 1e-3;   // m/s, separating
  const double v_t = 2e-3;   // m/s, sliding
  const double spin = 0.01;  // rad/s, about the normal
  const Quat tilt(Eigen::AngleAxisd(0.2, Vec3(1, 2, 0).normalized()));
  const Vec3 normal = tilt * Vec3::UnitZ();
  const Vec3 tangent = tilt * Vec3::UnitX();
  World reused(Settings(1e-3));
  World clipped(Settings(0.0));
  for (World* world : {&reused, &clipped}) {
    WorldSettings settings = world->settings();
    settings.gravity = Vec3::Zero();
    settings.solver.penetration_slop = 2 * d0;  // no position correction
    ASSERT_TRUE(world->SetSettings(settings).ok());
    Pose floor;
    floor.rotation = tilt;
    AddBox(world, StaticBox(Vec3(2, 2, 1), floor, 0.0));
    BoxSpec box;  // yawed on the floor, its bottom corners inside the floor's top face
    box.world_from_body.translation = normal * (1.0 - d0);
    box.world_from_body.rotation = tilt * Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
    box.linear_velocity = v_n * normal + v_t * tangent;
    box.angular_velocity = spin * normal;
    box.material = MakeMaterial(0.0, 0.0);
    AddBox(world, box);
  }
  const double dt = reused.settings().time_step;
  double largest_lag = 0.0;                     // m, of a reused point behind the clipped one
  for (int step = 0; step < 240 * 4; ++step) {  // until d = d0 / 5
    reused.Step();
    clipped.Step();
    SCOPED_TRACE(::testing::Message() << "step " << step);
    const double expected = d0 - v_n * step * dt;  // at the step's start
    for (World* world : {&reused, &clipped}) {
      EXPECT_EQ(world->contacts().size(), 4u);
      for (const ContactReport& report : world->contacts()) {
        EXPECT_NEAR(report.depth, expected, 1e-12);
        EXPECT_LT((report.normal_world - normal).norm(), 1e-12);
      }
    }
    // Only where the points sit may lag, by at most the reuse distance.
    ExpectMatch(reused.contacts(), clipped.contacts(), 1e-12,
                reused.settings().contact_reuse_distance, &largest_lag);
  }
  EXPECT_GT(largest_lag, 0.0) << "no manifold was reused";
}

// A box sliding on a static box decelerates at mu g, v(t) = v0 - mu g t, and
// its contact points stay at its corners: reuse leaves no stale points.
TEST(ManifoldReuseTest, SlidingBoxDeceleratesAtMuG) {
  const double mu = 0.3;
  const double v0 = 2.0;
  const double stop_time = v0 / (mu * kG);
  for (const double reuse_distance : {1e-3, 0.0}) {
    SCOPED_TRACE(reuse_distance);
    World world(Settings(reuse_distance));
    AddBox(&world, StaticBox(Vec3(10, 10, 1), Translation(0, 0, 0.5), mu));
    BoxSpec spec;
    spec.world_from_body = Translation(-2, 0, 1.5);
    spec.linear_velocity = Vec3(v0, 0, 0);
    spec.material = MakeMaterial(mu, 0.0);
    const BodyId box = AddBox(&world, spec);
    const double dt = world.settings().time_step;
    // A reused point sits midway between a corner, moved by at most the
    // reuse distance since the clip, and the floor below the clipped corner.
    const double max_lag = 0.5 * (reuse_distance + world.settings().solver.penetration_slop);
    double largest_lag = 0.0;  // m, of a point behind the box's nearest bottom corner
    for (int step = 0; step < 240; ++step) {
      const Pose start = world.GetPose(box);  // the reports describe this pose
      world.Step();
      for (const ContactReport& report : world.contacts()) {
        const Vec3 local = start.Inverse() * report.position_world;
        const Vec3 corner(std::copysign(0.5, local.x()), std::copysign(0.5, local.y()), -0.5);
        const double lag = (local - corner).norm();
        EXPECT_LT(lag, max_lag) << "t " << step * dt << " s";
        largest_lag = std::max(largest_lag, lag);
      }
      const double t = (step + 1) * dt;
      const double v = world.GetLinearVelocity(box).x();
      if (t < stop_time - 0.02) {
        EXPECT_NEAR((v0 - v) / (mu * kG * t), 1.0, 0.01) << "t " << t << " s, v " << v;
      } else if (t > stop_time + 0.02) {
        EXPECT_LT(world.GetLinearVelocity(box).norm(), 1e-3) << "t " << t << " s";
      }
    }
    // Below v = reuse distance / dt (the last 0.08 s) points are reused.
    if (reuse_distance > 0.0) {
      EXPECT_GT(largest_lag, 0.1 * reuse_distance);
    }
    // The constant friction force moves the box by the mean velocity of
    // each step, the closed form v0^2 / (2 mu g), but for the step in which
    // it stops: there the trapezoid is off by at most mu g dt^2 / 2.
    const double distance = v0 * v0 / (2 * mu * kG);
    const Vec3 moved = world.GetPose(box).translation - spec.world_from_body.translation;
    EXPECT_NEAR(moved.x(), distance, 0.5 * mu * kG * dt * dt);
    EXPECT_LT(std::abs(moved.y()), 1e-4);
    EXPECT_LT(std::abs(moved.z()), 1e-4);  // neither sinks nor hovers
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
