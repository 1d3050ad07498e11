#include "scene.h"

#include <algorithm>
#include <cmath>
#include <utility>

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

// Principal moments of a solid box of `mass` (kg) and full edge lengths
// `size` (m) about its centre.
Vec3 BoxInertia(double mass, const Vec3& size) {
  const Vec3 squared = size.cwiseProduct(size);
  return mass / 12.0 *
         Vec3(squared.y() + squared.z(), squared.x() + squared.z(), squared.x() + squared.y());
}

// A link whose collision shape is a box centred on its centre of mass.
BenchLink BoxLink(double mass, const Vec3& size, const Vec3& center) {
  BenchLink link;
  link.mass = mass;
  link.center_of_mass = center;
  link.inertia_diagonal = BoxInertia(mass, size);
  link.has_box = true;
  link.box_size = size;
  link.material = BenchMaterial{0.5, 0.0};
  return link;
}

BenchJoint Revolute(int parent, const Vec3& offset, const Vec3& axis, double position) {
  BenchJoint joint;
  joint.parent = parent;
  joint.parent_offset = offset;
  joint.axis = axis;
  joint.position = position;
  return joint;
}

// The boxes of arm_push: centres on a square lattice of kArmBoxPitch in the
// half annulus in front of the arm (x > 0) between kArmBoxInner and
// kArmBoxOuter from its yaw axis, nearest first.
constexpr double kArmBoxSize = 0.1;    // m
constexpr double kArmBoxPitch = 0.13;  // m between centres
constexpr double kArmBoxInner = 0.35;  // m
constexpr double kArmBoxOuter = 1.15;  // m

std::vector<Vec3> ArmBoxCentres(int count) {
  std::vector<std::pair<double, Vec3>> candidates;
  const int half = static_cast<int>(kArmBoxOuter / kArmBoxPitch) + 1;
  for (int i = 1; i <= half; ++i) {
    for (int j = -half; j <= half; ++j) {
      const Vec3 centre(i * kArmBoxPitch, j * kArmBoxPitch, 0.5 * kArmBoxSize);
      const double radius = centre.head<2>().norm();
      if (radius >= kArmBoxInner && radius <= kArmBoxOuter) candidates.emplace_back(radius, centre);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Vec3> centres;
  for (int k = 0; k < count && k < static_cast<int>(candidates.size()); ++k) {
    centres.push_back(candidates[k].second);
  }
  return centres;
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

namespace {

// chain_30's links: a point mass at the end of a massless 0.1 m rod (a
// small inertia keeps the mass matrix well posed, as in
// test/physics/articulation_test.cc).
BenchLink RodLink(double mass, double length) {
  BenchLink link;
  link.mass = mass;
  link.center_of_mass = Vec3(0.0, 0.0, -length);
  link.inertia_diagonal = Vec3::Constant(1e-4 * mass);
  return link;
}

}  // namespace

Scene MakeChain(int links, double seconds) {
  constexpr double kLength = 0.1;  // m per link
  Scene scene;
  scene.name = "chain_" + std::to_string(links);
  scene.kind = SceneKind::kChain;
  scene.seconds = seconds;
  BenchArticulation chain;
  chain.world_from_base.translation = Vec3(0.0, 0.0, 3.5);  // the tip never reaches the ground
  BenchLink anchor;
  anchor.mass = 1.0;
  anchor.inertia_diagonal = Vec3::Constant(0.01);
  chain.links.push_back(anchor);
  for (int i = 1; i <= links; ++i) {
    chain.links.push_back(RodLink(i == links ? 100.0 : 0.1, kLength));
    // The first joint at the anchor, turned 90 degrees: the chain starts
    // horizontal along -x.
    chain.joints.push_back(Revolute(i - 1, Vec3(0.0, 0.0, i == 1 ? 0.0 : -kLength), Vec3::UnitY(),
                                    i == 1 ? kPi / 2 : 0.0));
  }
  chain.motors.resize(chain.joints.size());
  scene.articulations.push_back(chain);
  return scene;
}

Scene MakeArmPush(int boxes, double seconds) {
  Scene scene;
  scene.name = "arm_push_" + std::to_string(boxes);
  scene.kind = SceneKind::kArmPush;
  scene.ground_material = BenchMaterial{0.5, 0.0};
  scene.seconds = seconds;
  for (const Vec3& centre : ArmBoxCentres(boxes)) {
    BenchBody box = UnitBox(centre, 0.0, 0.5);
    box.box_size = Vec3::Constant(kArmBoxSize);
    box.mass = 1.0;  // 1000 kg/m^3
    scene.bodies.push_back(box);
  }
  scene.top_body = 0;
  // Yaw about z at the base, a shoulder about y, an elbow about z; the
  // upper arm and forearm are 0.6 m boxes of 6 cm section whose centre line
  // is 6 cm above the ground, so they sweep through the boxes' middles.
  BenchArticulation arm;
  BenchLink base;
  base.mass = 10.0;
  base.inertia_diagonal = Vec3::Constant(0.1);
  arm.links = {base, BoxLink(2.0, Vec3(0.12, 0.12, 0.08), Vec3::Zero()),
               BoxLink(2.0, Vec3(0.5, 0.06, 0.06), Vec3(0.3, 0.0, 0.0)),
               BoxLink(1.5, Vec3(0.5, 0.06, 0.06), Vec3(0.3, 0.0, 0.0))};
  // Starts pointing along -y, behind the boxes, with the elbow bent back.
  arm.joints = {Revolute(0, Vec3(0.0, 0.0, 0.06), Vec3::UnitZ(), -0.5 * kPi - 0.05),
                Revolute(1, Vec3::Zero(), Vec3::UnitY(), 0.0),
                Revolute(2, Vec3(0.6, 0.0, 0.0), Vec3::UnitZ(), -0.3)};
  arm.joints[0].effort_limit = 1000.0;
  arm.joints[1].effort_limit = 500.0;
  arm.joints[2].effort_limit = 500.0;
  // The yaw motor sweeps forward through the boxes for half the run and back
  // for the other half; the shoulder and elbow motors hold still.
  arm.motors = {{MotorPhase{0.0, 0.6}, MotorPhase{0.5 * seconds, -0.6}},
                {MotorPhase{0.0, 0.0}},
                {MotorPhase{0.0, 0.0}}};
  scene.articulations.push_back(arm);
  scene.driven_joint = 0;
  return scene;
}

Scene AtStepRate(Scene scene, int hz) {
  scene.time_step = 1.0 / hz;
  if (hz != 240) scene.name += "_" + std::to_string(hz) + "hz";
  return scene;
}

double EnergyScale(const Scene& scene) {
  const Vec3 origin = scene.articulations.empty()
                          ? Vec3::Zero()
                          : scene.articulations[0].world_from_base.translation;
  double scale = 0.0;
  for (const BenchBody& body : scene.bodies) {
    scale += body.mass * kGravity * (body.world_from_body.translation - origin).norm();
  }
  for (const BenchArticulation& articulation : scene.articulations) {
    // Each link's frame at the start: its parent's moved by the joint's
    // offset and turned by its angle (BenchJoint).
    std::vector<Pose> world_from_link = {articulation.world_from_base};
    for (const BenchJoint& joint : articulation.joints) {
      Pose child = world_from_link[joint.parent];
      child.translation = child * joint.parent_offset;
      child.rotation = child.rotation * Quat(Eigen::AngleAxisd(joint.position, joint.axis));
      world_from_link.push_back(child);
    }
    for (std::size_t i = 1; i < articulation.links.size(); ++i) {
      const BenchLink& link = articulation.links[i];
      scale += link.mass * kGravity * (world_from_link[i] * link.center_of_mass - origin).norm();
    }
  }
  return scale;
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

Scene MakeTerrain(int count, int triangles, double seconds, double amplitude) {
  Scene scene = DropBoxes(count, Hills{amplitude, 3.0}, seconds);
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
