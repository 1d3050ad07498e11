// Times box-box narrow-phase calls, cold (the witness is reset before every
// call, so the full separating-axis test runs) and warm (the witness of the
// previous call is kept, as the world keeps it per pair from step to step).
//
// Scenes, each with small per-call motion so that nothing is constant-folded:
//  - "resting": a box lying on another, offset, 1 mm deep (4-point manifold);
//  - "edge": two boxes crossed edge on edge, 1 mm deep (1 point);
//  - "separated": a turned box 5 mm above another (no contact): the warm
//    witness ends the call after one face or edge-pair test.
//
// Usage: narrow_phase_bench [calls]   (default 1,000,000 timed calls per case)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>

#include "physics/collision/narrow_phase.h"

namespace rigid_body_sim::physics {
namespace {

struct Scene {
  const char* name;
  Pose world_from_a;
  Pose world_from_b;
};

Quat AxisAngle(double angle, const Vec3& axis) {
  return Quat(Eigen::AngleAxisd(angle, axis.normalized()));
}

double TimeCalls(const Scene& scene, const ShapeGeometry& box, bool warm, int calls,
                 int* touching_calls) {
  SeparatingWitness witness;
  ContactManifold manifold;
  CollideInput input{&box, scene.world_from_a, &box, scene.world_from_b, 0.0};
  int touching = 0;
  // Processor time, not wall time, so that other load on the machine does
  // not count.
  const std::clock_t start = std::clock();
  for (int i = 0; i < calls; ++i) {
    if (!warm) witness = SeparatingWitness{};
    // A 1 um wobble keeps the configuration but changes the inputs.
    input.world_from_a.translation.x() = scene.world_from_a.translation.x() + 1e-6 * (i & 7);
    touching += Collide(input, &witness, &manifold) ? 1 : 0;
  }
  const std::clock_t stop = std::clock();
  *touching_calls = touching;
  return 1e9 * static_cast<double>(stop - start) / CLOCKS_PER_SEC / calls;
}

int Main(int argc, char** argv) {
  const int calls = argc > 1 ? std::max(1, std::atoi(argv[1])) : 1000000;
  const ShapeGeometry box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1, 1, 1)));
  const double h = std::sqrt(0.5);
  // A unit cube turned by R reaches 0.5 (|R20| + |R21| + |R22|) below its
  // centre; put that lowest vertex 5 mm above the other cube's top.
  const Quat turned = AxisAngle(0.7, Vec3(1, 2, 3));
  const double reach_down = 0.5 * turned.toRotationMatrix().row(2).cwiseAbs().sum();
  const Scene scenes[] = {
      {"resting", Pose{Vec3(0.3, 0.2, 0.999), Quat::Identity()}, Pose::Identity()},
      {"edge", Pose{Vec3(0.1, -0.2, 2 * h - 0.001), AxisAngle(kPi / 4, Vec3::UnitY())},
       Pose{Vec3::Zero(), AxisAngle(kPi / 4, Vec3::UnitX())}},
      {"separated", Pose{Vec3(0.2, 0.1, 0.505 + reach_down), turned}, Pose::Identity()},
  };
  std::printf("box-box narrow phase, %d calls per case\n", calls);
  std::printf("%-10s %12s %12s %10s\n", "scene", "cold ns", "warm ns", "points");
  for (const Scene& scene : scenes) {
    int touching_cold = 0;
    int touching_warm = 0;
    const double cold = TimeCalls(scene, box, false, calls, &touching_cold);
    const double warm = TimeCalls(scene, box, true, calls, &touching_warm);
    SeparatingWitness witness;
    ContactManifold manifold;
    Collide({&box, scene.world_from_a, &box, scene.world_from_b, 0.0}, &witness, &manifold);
    std::printf("%-10s %12.1f %12.1f %10d%s\n", scene.name, cold, warm, manifold.point_count,
                touching_cold == touching_warm ? "" : "  (cold and warm disagree!)");
  }
  return 0;
}

}  // namespace
}  // namespace rigid_body_sim::physics

int main(int argc, char** argv) { return rigid_body_sim::physics::Main(argc, argv); }
