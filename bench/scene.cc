#include "scene.h"

#include <cmath>

namespace rigid_body_sim::bench {
namespace {

// Two unit boxes of one layer, both yawed by theta, with centres 1.1 m apart
// along x are separated along their own x axis only while 1.1 cos(theta) >= 1,
// i.e. theta <= 0.430 rad (along their y axis, 1.1 sin(theta) < 1 for these
// angles). Layers therefore take the yaws 0, 0.1, ..., 0.4 rad in turn
// instead of growing without end, which from the sixth layer on would start
// neighbours 0.2 m deep inside each other.
constexpr double kPileYawStep = 0.1;  // rad per layer
constexpr int kPileYawCycle = 5;      // layers

BenchBody UnitBox(const Vec3& position, double yaw, double friction) {
  BenchBody body;
  body.shape = BenchBody::Shape::kBox;
  body.box_size = Vec3::Ones();
  body.mass = 1.0;
  body.world_from_body.translation = position;
  body.world_from_body.rotation = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  body.material.friction = friction;
  body.material.restitution = 0.0;
  return body;
}

}  // namespace

Scene MakePile(int count, double seconds) {
  Scene scene;
  scene.name = "pile_" + std::to_string(count);
  scene.kind = SceneKind::kPile;
  scene.ground_material = BenchMaterial{0.5, 0.0};
  scene.seconds = seconds;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count)) - 1e-9));
  const int per_layer = side * side;
  const double half_width = 0.5 * (side - 1) * 1.1;
  for (int k = 0; k < count; ++k) {
    const int layer = k / per_layer;
    const int column = k % per_layer;
    const Vec3 position((column % side) * 1.1 - half_width, (column / side) * 1.1 - half_width,
                        0.6 + 1.2 * layer);
    scene.bodies.push_back(UnitBox(position, kPileYawStep * (layer % kPileYawCycle), 0.5));
  }
  // The last box placed is in the top layer.
  scene.top_body = count - 1;
  return scene;
}

Scene MakePyramid(int rows, double seconds) {
  Scene scene;
  scene.name = "pyramid_" + std::to_string(rows);
  scene.kind = SceneKind::kPyramid;
  scene.ground_material = BenchMaterial{0.6, 0.0};
  scene.seconds = seconds;
  for (int row = 0; row < rows; ++row) {
    const int boxes = rows - row;
    for (int i = 0; i < boxes; ++i) {
      const Vec3 position(i - 0.5 * (boxes - 1), 0.0, 0.5 + row);
      scene.bodies.push_back(UnitBox(position, 0.0, 0.6));
    }
  }
  scene.top_body = static_cast<int>(scene.bodies.size()) - 1;
  return scene;
}

Scene MakeBounce() {
  Scene scene;
  scene.name = "bounce";
  scene.kind = SceneKind::kBounce;
  scene.ground_material = BenchMaterial{0.5, 0.0};
  scene.seconds = 1.0;  // falls 0.45 s, rises 0.23 s to the first apex
  scene.drop_height = 1.0;
  BenchBody sphere;
  sphere.shape = BenchBody::Shape::kSphere;
  sphere.sphere_radius = 0.1;
  sphere.mass = 1.0;
  sphere.world_from_body.translation = Vec3(0.0, 0.0, scene.drop_height + sphere.sphere_radius);
  sphere.material = BenchMaterial{0.5, 0.5};
  scene.bodies.push_back(sphere);
  scene.top_body = 0;
  return scene;
}

Scene MakeIncline(double degrees) {
  Scene scene;
  scene.name = "incline_" + std::to_string(static_cast<int>(std::lround(degrees)));
  scene.kind = SceneKind::kIncline;
  scene.slope_degrees = degrees;
  scene.seconds = 2.0;
  // The slope descends along +x: the ground is pitched about +y.
  const Quat slope(Eigen::AngleAxisd(degrees * kPi / 180.0, Vec3::UnitY()));
  scene.world_from_ground.rotation = slope;
  scene.ground_material = BenchMaterial{0.5, 0.0};
  BenchBody box = UnitBox(Vec3::Zero(), 0.0, 0.5);
  box.world_from_body.rotation = slope;
  box.world_from_body.translation = slope * Vec3(0.0, 0.0, 0.5);
  scene.bodies.push_back(box);
  scene.top_body = 0;
  return scene;
}

double Hills::HeightAt(double x, double y) const {
  return amplitude * std::sin(x / wavelength) * std::cos(y / wavelength);
}

namespace {

constexpr double kTerrainSize = 40.0;  // m, square, centred on the origin

// The drop of the terrain scenes over `hills` (flat when the amplitude is 0).
Scene DropBoxes(int count, const Hills& hills, double seconds) {
  Scene scene;
  scene.kind = SceneKind::kTerrain;
  scene.seconds = seconds;
  scene.hills = hills;
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  for (int i = 0; i < count; ++i) {
    BenchBody body;
    body.box_size = Vec3::Ones();
    body.material.friction = 0.5;
    const double x = 3.0 * (i % side - 0.5 * (side - 1));
    const double y = 3.0 * (i / side - 0.5 * (side - 1));
    body.world_from_body.translation = Vec3(x, y, hills.HeightAt(x, y) + 1.5 + 0.01 * i);
    body.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3 * i, Vec3::UnitZ()));
    scene.bodies.push_back(body);
  }
  scene.top_body = count - 1;
  return scene;
}

}  // namespace

Scene MakeTerrain(int count, int triangles, double seconds) {
  Scene scene = DropBoxes(count, Hills{0.5, 3.0}, seconds);
  scene.name = "terrain_" + std::to_string(count);
  const int cells = static_cast<int>(std::ceil(std::sqrt(0.5 * triangles)));
  const double cell = kTerrainSize / cells;
  const double x0 = -0.5 * kTerrainSize;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      const double x = x0 + i * cell;
      const double y = x0 + j * cell;
      scene.terrain.vertices.emplace_back(x, y, scene.hills.HeightAt(x, y));
    }
  }
  const auto at = [cells](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      scene.terrain.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      scene.terrain.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return scene;
}

Scene MakeFlatTerrain(int count, double seconds) {
  Scene scene = DropBoxes(count, Hills{0.0, 3.0}, seconds);
  scene.name = "terrain_flat_" + std::to_string(count);
  return scene;
}

}  // namespace rigid_body_sim::bench
