#include "rigid_body_sim/io/urdf_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::kPi;
using physics::MassProperties;
using physics::Mat3;
using physics::Pose;
using physics::Quat;
using physics::Result;
using physics::Vec3;

const std::string kDataDir = RBS_TEST_DATA_DIR;

// The chamfered box of test/data/make_test_meshes.py.
const Vec3 kHalf(0.25, 0.125, 0.0625);
const Vec3 kCut(0.125, 0.0625, 0.03125);

// The box minus the corner tetrahedron, whose centroid is the corner minus a
// quarter of the cut lengths.
double ChamferedBoxVolume() { return 8.0 * kHalf.prod() - kCut.prod() / 6.0; }
Vec3 ChamferedBoxCentroid() {
  const double tetra_volume = kCut.prod() / 6.0;
  const Vec3 tetra_centroid = kHalf - kCut / 4.0;
  return -tetra_volume * tetra_centroid / ChamferedBoxVolume();
}

// Resolves package://rigid_body_sim/ to the source tree, as the node does.
Result<std::string> ResolvePackage(const std::string& uri) {
  const std::string prefix = "package://rigid_body_sim/";
  if (uri.rfind(prefix, 0) == 0)
    return std::string(RBS_SOURCE_DIR) + "/" + uri.substr(prefix.size());
  return ResolveFileUri(uri);
}

UrdfLoadOptions PackageOptions() {
  UrdfLoadOptions options;
  options.resolver = ResolvePackage;
  return options;
}

void ExpectPoseNear(const Pose& actual, const Pose& expected, double tolerance) {
  EXPECT_LE((actual.translation - expected.translation).norm(), tolerance)
      << actual.translation.transpose() << " vs " << expected.translation.transpose();
  EXPECT_LE(actual.rotation.angularDistance(expected.rotation), tolerance);
}

const ConvexPolyhedron& PolyhedronOf(const LoadedShape& shape) {
  return *std::get<std::shared_ptr<const ConvexPolyhedron>>(shape.shape.geometry);
}

// Base link: a 0.2 m box and a cylinder (r 0.1, l 0.2) above it; no
// <inertial>. Tool link, fixed 0.5 m along x and turned 90 degrees about z:
// a sphere, the chamfered box (binary STL) and the same box twice as large
// from the Y_UP centimetre DAE; no <inertial>; friction 0.9.
std::string AssemblyUrdf() {
  return R"(<?xml version="1.0"?>
<robot name="assembly">
  <link name="base_link">
    <collision name="block">
      <geometry><box size="0.2 0.2 0.2"/></geometry>
    </collision>
    <collision name="post">
      <origin xyz="0 0 0.2"/>
      <geometry><cylinder radius="0.1" length="0.2"/></geometry>
    </collision>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="base_link"/>
    <child link="tool"/>
    <origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="tool">
    <collision name="ball">
      <geometry><sphere radius="0.05"/></geometry>
    </collision>
    <collision name="stl_box">
      <origin xyz="0 0.3 0"/>
      <geometry><mesh filename="file://)" +
         kDataDir + R"(/chamfered_box_binary.stl"/></geometry>
    </collision>
    <collision name="dae_box">
      <origin xyz="0 -0.3 0"/>
      <geometry><mesh filename="package://rigid_body_sim/test/data/chamfered_box_yup_cm.dae" scale="2 2 2"/></geometry>
    </collision>
  </link>
  <gazebo reference="tool">
    <mu1>0.9</mu1>
  </gazebo>
</robot>)";
}

TEST(UrdfLoaderTest, CompoundModelWithFixedJointMergesIntoOneBody) {
  const Result<LoadedModel> model = LoadUrdfString(AssemblyUrdf(), PackageOptions());
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(model->name, "assembly");
  EXPECT_EQ(model->root_link, "base_link");
  EXPECT_FALSE(model->is_static);

  const Pose root_from_tool{Vec3(0.5, 0.0, 0.0), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))};
  ASSERT_EQ(model->links.size(), 2u);
  EXPECT_EQ(model->links[0].link_name, "base_link");
  ExpectPoseNear(model->links[0].root_from_link, Pose::Identity(), 1e-15);
  EXPECT_EQ(model->links[1].link_name, "tool");
  ExpectPoseNear(model->links[1].root_from_link, root_from_tool, 1e-12);

  ASSERT_EQ(model->shapes.size(), 5u);
  const std::vector<Vec3> shape_origins = {Vec3(0, 0, 0), Vec3(0, 0, 0.2), Vec3(0.5, 0, 0),
                                           Vec3(0.2, 0, 0), Vec3(0.8, 0, 0)};
  for (size_t i = 0; i < 5; ++i) {
    SCOPED_TRACE(i);
    EXPECT_LE((model->shapes[i].shape.body_from_shape.translation - shape_origins[i]).norm(),
              1e-12);
    const bool on_tool = i >= 2;
    EXPECT_EQ(model->shapes[i].link_name, on_tool ? "tool" : "base_link");
    EXPECT_EQ(model->shapes[i].friction_from_urdf, on_tool);
    if (on_tool) {
      EXPECT_DOUBLE_EQ(model->shapes[i].shape.material.friction, 0.9);
    }
  }
  // Box: 8 vertices; cylinder and sphere exact; meshes: hulls of the
  // chamfered box, the DAE one scaled by 2.
  EXPECT_EQ(PolyhedronOf(model->shapes[0]).vertices.size(), 8u);
  const auto* cylinder = std::get_if<physics::Cylinder>(&model->shapes[1].shape.geometry);
  ASSERT_NE(cylinder, nullptr);
  EXPECT_DOUBLE_EQ(cylinder->radius, 0.1);
  EXPECT_DOUBLE_EQ(cylinder->half_length, 0.1);  // half of length 0.2
  ASSERT_TRUE(std::holds_alternative<physics::Sphere>(model->shapes[2].shape.geometry));
  EXPECT_DOUBLE_EQ(std::get<physics::Sphere>(model->shapes[2].shape.geometry).radius, 0.05);
  const ConvexPolyhedron& stl_hull = PolyhedronOf(model->shapes[3]);
  const ConvexPolyhedron& dae_hull = PolyhedronOf(model->shapes[4]);
  EXPECT_EQ(stl_hull.vertices.size(), 10u);
  EXPECT_EQ(dae_hull.vertices.size(), 10u);
  Vec3 dae_extent = Vec3::Zero();
  for (const Vec3& v : dae_hull.vertices) dae_extent = dae_extent.cwiseMax(v.cwiseAbs());
  EXPECT_LE((dae_extent - 2.0 * kHalf).norm(), 1e-6);

  // Masses at 1000 kg/m^3 from the analytic volumes; centre of mass from
  // the shape origins in the root frame (the chamfered box centroid turned
  // by the tool rotation).
  const double density = 1000.0;
  const double box_mass = density * 0.008;
  const double cylinder_mass = density * kPi * 0.01 * 0.2;
  const double sphere_mass = density * 4.0 / 3.0 * kPi * 0.05 * 0.05 * 0.05;
  const double stl_mass = density * ChamferedBoxVolume();
  const double dae_mass = 8.0 * stl_mass;
  const double total = box_mass + cylinder_mass + sphere_mass + stl_mass + dae_mass;
  EXPECT_NEAR(model->mass_properties.mass, total, 1e-9 * total);
  const Vec3 stl_centroid = root_from_tool * (Vec3(0, 0.3, 0) + ChamferedBoxCentroid());
  const Vec3 dae_centroid = root_from_tool * (Vec3(0, -0.3, 0) + 2.0 * ChamferedBoxCentroid());
  const Vec3 center = (cylinder_mass * Vec3(0, 0, 0.2) + sphere_mass * Vec3(0.5, 0, 0) +
                       stl_mass * stl_centroid + dae_mass * dae_centroid) /
                      total;
  EXPECT_LE((model->mass_properties.center_of_mass - center).norm(), 1e-9);

  // Inertia: the analytic primitives and reference hulls placed by hand.
  const auto place = [](MassProperties part, const Pose& pose) {
    return physics::TransformMassProperties(part, pose);
  };
  const Pose tool_stl = root_from_tool * Pose{Vec3(0, 0.3, 0), Quat::Identity()};
  const Pose tool_dae = root_from_tool * Pose{Vec3(0, -0.3, 0), Quat::Identity()};
  const MassProperties expected = physics::CombineMassProperties({
      physics::BoxMassProperties(density, Vec3(0.2, 0.2, 0.2)),
      place(physics::CylinderMassProperties(density, 0.1, 0.2),
            Pose{Vec3(0, 0, 0.2), Quat::Identity()}),
      place(physics::SphereMassProperties(density, 0.05), root_from_tool),
      place(physics::PolyhedronMassProperties(density, stl_hull), tool_stl),
      place(physics::PolyhedronMassProperties(density, dae_hull), tool_dae),
  });
  EXPECT_LE((model->mass_properties.inertia_about_com - expected.inertia_about_com).norm(),
            1e-9 * expected.inertia_about_com.norm());

  ASSERT_EQ(model->warnings.size(), 2u);
  EXPECT_NE(model->warnings[0].find("link 'base_link' has no <inertial>"), std::string::npos);
  EXPECT_NE(model->warnings[0].find("1000 kg/m^3"), std::string::npos);
  EXPECT_NE(model->warnings[1].find("link 'tool'"), std::string::npos);
}

// The same mesh at the same scale is hulled once and shared.
TEST(UrdfLoaderTest, RepeatedMeshSharesOneHull) {
  const std::string mesh = "file://" + kDataDir + "/chamfered_box.obj";
  const std::string xml = R"(<robot name="pair"><link name="base_link">
    <collision><geometry><mesh filename=")" +
                          mesh + R"("/></geometry></collision>
    <collision><origin xyz="1 0 0"/><geometry><mesh filename=")" +
                          mesh + R"("/></geometry></collision>
    </link></robot>)";
  const Result<LoadedModel> model = LoadUrdfString(xml);
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->shapes.size(), 2u);
  EXPECT_EQ(std::get<std::shared_ptr<const ConvexPolyhedron>>(model->shapes[0].shape.geometry),
            std::get<std::shared_ptr<const ConvexPolyhedron>>(model->shapes[1].shape.geometry));
  EXPECT_NEAR(model->mass_properties.mass, 2000.0 * ChamferedBoxVolume(), 1e-9);
}

// Fixed to `world`: static, placed by the world joint. The base link's
// <inertial> is given in a frame 0.1 m along x and turned 90 degrees about
// z, so its principal moments (1, 2, 3) appear as (2, 1, 3) in the link frame.
TEST(UrdfLoaderTest, WorldJointMakesAStaticBodyAndInertialFramesAreHonoured) {
  const std::string xml = R"(<robot name="fixture">
  <link name="world"/>
  <joint name="anchor" type="fixed">
    <parent link="world"/><child link="base"/>
    <origin xyz="1 2 3" rpy="0 0 0"/>
  </joint>
  <link name="base">
    <inertial>
      <origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/>
      <mass value="4"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/>
    </inertial>
    <collision><geometry><box size="1 1 1"/></geometry></collision>
  </link>
  <joint name="shelf_joint" type="fixed">
    <parent link="base"/><child link="shelf"/>
    <origin xyz="0 0 1"/>
  </joint>
  <link name="shelf">
    <collision><geometry><box size="1 1 0.1"/></geometry></collision>
  </link>
</robot>)";
  const Result<LoadedModel> model = LoadUrdfString(xml);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_TRUE(model->is_static);
  EXPECT_EQ(model->root_link, "base");
  ExpectPoseNear(model->world_from_root, Pose{Vec3(1, 2, 3), Quat::Identity()}, 1e-15);
  ASSERT_EQ(model->links.size(), 2u);
  ExpectPoseNear(model->links[1].root_from_link, Pose{Vec3(0, 0, 1), Quat::Identity()}, 1e-15);
  EXPECT_TRUE(model->warnings.empty());
  ASSERT_EQ(model->shapes.size(), 2u);
  EXPECT_LE((model->shapes[1].shape.body_from_shape.translation - Vec3(0, 0, 1)).norm(), 1e-15);

  // 4 kg at (0.1, 0, 0) plus the shelf, 100 kg at (0, 0, 1).
  EXPECT_NEAR(model->mass_properties.mass, 104.0, 1e-9);
  EXPECT_LE((model->mass_properties.center_of_mass - Vec3(0.4, 0, 100) / 104.0).norm(), 1e-12);
  const MassProperties base_in_link{4.0, Vec3(0.1, 0, 0), Mat3(Vec3(2, 1, 3).asDiagonal())};
  MassProperties shelf = physics::BoxMassProperties(1000.0, Vec3(1, 1, 0.1));
  shelf.center_of_mass = Vec3(0, 0, 1);
  const MassProperties expected = physics::CombineMassProperties({base_in_link, shelf});
  EXPECT_LE((model->mass_properties.inertia_about_com - expected.inertia_about_com).norm(), 1e-9);
}

// Every URDF shipped in urdf/ loads as the node loads it (movable joints
// simulated), the six sample bodies and the demo arm among them.
TEST(UrdfLoaderTest, EveryShippedUrdfLoads) {
  std::set<std::string> loaded;
  UrdfLoadOptions options = PackageOptions();
  options.articulate = true;
  for (const auto& entry : std::filesystem::directory_iterator(RBS_URDF_DIR)) {
    if (entry.path().extension() != ".urdf") continue;
    SCOPED_TRACE(entry.path().string());
    const Result<LoadedModel> model = LoadUrdfFile(entry.path().string(), options);
    ASSERT_TRUE(model.ok()) << model.message();
    EXPECT_FALSE(model->shapes.empty());
    if (model->articulated) {
      std::vector<std::string> warnings;
      const Result<physics::ArticulationDef> def = MakeArticulationDef(*model, &warnings);
      ASSERT_TRUE(def.ok()) << def.message();
      for (const physics::LinkDef& link : def->links) {
        EXPECT_TRUE(physics::ValidateMassProperties(link.mass_properties).ok()) << link.name;
      }
    }
    if (!model->is_static) {
      EXPECT_TRUE(physics::ValidateMassProperties(model->mass_properties).ok());
    }
    loaded.insert(entry.path().filename().string());
  }
  for (const char* sample : {"box.urdf", "sphere.urdf", "cylinder.urdf", "mesh_object.urdf",
                             "table.urdf", "compound.urdf", "demo_arm.urdf"}) {
    EXPECT_EQ(loaded.count(sample), 1u) << sample;
  }
}

TEST(UrdfLoaderTest, ShippedUrdfsHaveTheirStatedProperties) {
  const auto load = [](const std::string& name) {
    return LoadUrdfFile(std::string(RBS_URDF_DIR) + "/" + name, PackageOptions());
  };
  for (const char* sample : {"box.urdf", "sphere.urdf", "cylinder.urdf", "mesh_object.urdf",
                             "table.urdf", "compound.urdf"}) {
    const Result<LoadedModel> model = load(sample);
    ASSERT_TRUE(model.ok()) << sample << ": " << model.message();
    EXPECT_EQ(model->root_link, "base_link") << sample;
    EXPECT_TRUE(model->warnings.empty()) << sample;
  }
  const Result<LoadedModel> box = load("box.urdf");
  ASSERT_TRUE(box.ok()) << box.message();
  EXPECT_DOUBLE_EQ(box->mass_properties.mass, 1.0);
  EXPECT_LE((box->mass_properties.inertia_about_com - Mat3::Identity() / 6.0).norm(), 1e-12);
  EXPECT_EQ(PolyhedronOf(box->shapes[0]).vertices.size(), 8u);
  EXPECT_FALSE(box->shapes[0].friction_from_urdf);

  const Result<LoadedModel> sphere = load("sphere.urdf");
  ASSERT_TRUE(sphere.ok()) << sphere.message();
  EXPECT_DOUBLE_EQ(std::get<physics::Sphere>(sphere->shapes[0].shape.geometry).radius, 0.1);
  EXPECT_TRUE(sphere->shapes[0].friction_from_urdf);
  EXPECT_DOUBLE_EQ(sphere->shapes[0].shape.material.friction, 0.8);

  // The pebble mesh (182 vertices of an ellipsoid) is hulled without
  // simplification; its extents are the semi-axes.
  const Result<LoadedModel> pebble = load("mesh_object.urdf");
  ASSERT_TRUE(pebble.ok()) << pebble.message();
  const ConvexPolyhedron& hull = PolyhedronOf(pebble->shapes[0]);
  EXPECT_EQ(hull.vertices.size(), 182u);
  Vec3 extent = Vec3::Zero();
  for (const Vec3& v : hull.vertices) extent = extent.cwiseMax(v.cwiseAbs());
  EXPECT_LE((extent - Vec3(0.08, 0.05, 0.03)).norm(), 1e-7);

  const Result<LoadedModel> table = load("table.urdf");
  ASSERT_TRUE(table.ok()) << table.message();
  EXPECT_TRUE(table->is_static);
  EXPECT_EQ(table->shapes.size(), 5u);

  // Hammer: 0.25 kg handle with its centre of mass at z = 0.12 m and a 0.6 kg
  // head at z = 0.32 m.
  const Result<LoadedModel> hammer = load("compound.urdf");
  ASSERT_TRUE(hammer.ok()) << hammer.message();
  EXPECT_EQ(hammer->shapes.size(), 3u);
  EXPECT_NEAR(hammer->mass_properties.mass, 0.85, 1e-12);
  EXPECT_NEAR(hammer->mass_properties.center_of_mass.z(), (0.25 * 0.12 + 0.6 * 0.32) / 0.85, 1e-12);
  EXPECT_FALSE(hammer->shapes[0].friction_from_urdf);
  EXPECT_TRUE(hammer->shapes[2].friction_from_urdf);
}

// Relative mesh paths in a URDF file are relative to that file.
TEST(UrdfLoaderTest, RelativeMeshPathsFollowTheUrdfFile) {
  const Result<LoadedModel> model = LoadUrdfFile(kDataDir + "/relative_mesh.urdf");
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(PolyhedronOf(model->shapes[0]).vertices.size(), 10u);
}

std::string OneLinkUrdf(const std::string& link_body) {
  return "<robot name=\"bad\"><link name=\"part\">" + link_body + "</link></robot>";
}

std::string MeshCollision(const std::string& file) {
  return "<collision name=\"shell\"><geometry><mesh filename=\"" + kDataDir + "/" + file +
         "\"/></geometry></collision>";
}

std::string BoxInertial(const std::string& mass, const std::string& inertia) {
  return "<inertial><mass value=\"" + mass + "\"/><inertia " + inertia +
         "/></inertial><collision><geometry><box size=\"1 1 1\"/></geometry></collision>";
}

struct BadCase {
  std::string description;
  std::string xml;
  std::vector<std::string> expected;  // fragments of the message
};

class UrdfBadInputTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(UrdfBadInputTest, IsRefusedWithAMessageNamingTheElement) {
  const BadCase& bad = GetParam();
  const Result<LoadedModel> model = LoadUrdfString(bad.xml);
  ASSERT_FALSE(model.ok()) << bad.description;
  for (const std::string& fragment : bad.expected) {
    EXPECT_NE(model.message().find(fragment), std::string::npos)
        << bad.description << ": '" << fragment << "' not in: " << model.message();
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllCases, UrdfBadInputTest,
    ::testing::Values(
        BadCase{"malformed xml",
                "<robot name=\"x\"><link name=\"a\"></robot>",
                {"malformed URDF XML at line 1"}},
        BadCase{"not a robot", "<model name=\"x\"/>", {"<robot>"}},
        BadCase{"missing mesh",
                OneLinkUrdf(MeshCollision("no_such_mesh.stl")),
                {"link 'part' <collision> 'shell'", "no_such_mesh.stl", "does not exist"}},
        BadCase{"unsupported format",
                OneLinkUrdf(MeshCollision("chamfered_box.off")),
                {"link 'part' <collision> 'shell'", "chamfered_box.off", "unsupported format"}},
        BadCase{"empty mesh",
                OneLinkUrdf(MeshCollision("empty.stl")),
                {"link 'part' <collision> 'shell'", "empty.stl"}},
        BadCase{"nan vertex",
                OneLinkUrdf(MeshCollision("nan_vertex.stl")),
                {"link 'part' <collision> 'shell'", "nan_vertex.stl", "not finite"}},
        BadCase{"package uri without resolver",
                OneLinkUrdf("<collision><geometry><mesh filename=\"package://other/m.stl\"/>"
                            "</geometry></collision>"),
                {"link 'part' <collision> 0", "package://other/m.stl"}},
        BadCase{"movable joint",
                "<robot name=\"arm\"><link name=\"a\"><collision><geometry><box size=\"1 1 1\"/>"
                "</geometry></collision></link><link name=\"b\"/><joint name=\"elbow\" "
                "type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/>"
                "<limit lower=\"0\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint></robot>",
                {"joint 'elbow' is revolute"}},
        BadCase{"floating joint",
                "<robot name=\"arm\"><link name=\"a\"><collision><geometry><box size=\"1 1 1\"/>"
                "</geometry></collision></link><link name=\"b\"/><joint name=\"free\" "
                "type=\"floating\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                {"joint 'free' is floating"}},
        BadCase{"negative mass",
                OneLinkUrdf(BoxInertial("-2", "ixx=\"1\" iyy=\"1\" izz=\"1\"")),
                {"link 'part': invalid <inertial>"}},
        BadCase{"inertia not positive definite",
                OneLinkUrdf(BoxInertial("1", "ixx=\"1\" iyy=\"-1\" izz=\"1\"")),
                {"link 'part': invalid <inertial>"}},
        BadCase{"inertia breaks triangle inequality",
                OneLinkUrdf(BoxInertial("1", "ixx=\"1\" iyy=\"1\" izz=\"3\"")),
                {"link 'part': invalid <inertial>"}},
        BadCase{"flat mesh scale",
                OneLinkUrdf("<collision name=\"shell\"><geometry><mesh filename=\"" + kDataDir +
                            "/chamfered_box.obj\" scale=\"1 1 0\"/></geometry></collision>"),
                {"link 'part' <collision> 'shell'", "scale"}},
        BadCase{"bad friction",
                "<robot name=\"x\"><link name=\"a\"><collision><geometry><sphere radius=\"1\"/>"
                "</geometry></collision></link><gazebo reference=\"a\"><mu1>-1</mu1></gazebo>"
                "</robot>",
                {"<gazebo reference='a'> <mu1>", "'-1'"}},
        BadCase{"joint to unknown link",
                "<robot name=\"x\"><link name=\"a\"><collision><geometry><sphere "
                "radius=\"1\"/></geometry></collision></link><joint name=\"j\" type=\"fixed\">"
                "<parent link=\"a\"/><child link=\"ghost\"/></joint></robot>",
                {"urdfdom rejected the URDF", "ghost"}},
        BadCase{"no collision",
                "<robot name=\"ghost\"><link name=\"a\"/></robot>",
                {"model 'ghost' has no <collision> elements"}}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string name = info.param.description;
      std::replace(name.begin(), name.end(), ' ', '_');
      return name;
    });

// An arm: box 'base' (2 kg), an elbow turning about z at 1 m up x, a 0.5 kg
// sphere link 'forearm', and a slider along y to a 0.25 kg link 'tip'.
std::string ArmUrdf() {
  return "<robot name=\"arm\">"
         "<link name=\"base\"><inertial><mass value=\"2\"/><inertia ixx=\"1\" iyy=\"1\" "
         "izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial><collision><geometry>"
         "<box size=\"1 1 1\"/></geometry></collision></link>"
         "<link name=\"forearm\"><inertial><mass value=\"0.5\"/><inertia ixx=\"0.1\" "
         "iyy=\"0.1\" izz=\"0.1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial><collision>"
         "<origin xyz=\"1 0 0\"/><geometry><sphere radius=\"0.2\"/></geometry></collision>"
         "</link>"
         "<link name=\"tip\"><inertial><mass value=\"0.25\"/><inertia ixx=\"0.01\" "
         "iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"
         "<joint name=\"elbow\" type=\"revolute\"><parent link=\"base\"/>"
         "<child link=\"forearm\"/><origin xyz=\"1 0 0\"/><axis xyz=\"0 0 1\"/>"
         "<limit lower=\"-1\" upper=\"2\" effort=\"1\" velocity=\"1\"/></joint>"
         "<joint name=\"slider\" type=\"prismatic\"><parent link=\"forearm\"/>"
         "<child link=\"tip\"/><origin xyz=\"1 0 0\"/><axis xyz=\"0 1 0\"/>"
         "<limit lower=\"0\" upper=\"0.5\" effort=\"1\" velocity=\"1\"/></joint>"
         "</robot>";
}

TEST(UrdfLoaderTest, MovableJointsAreWeldedAtTheirGivenPositions) {
  UrdfLoadOptions options;
  options.weld_movable_joints = true;
  options.joint_positions = {{"elbow", kPi / 2.0}, {"slider", 0.5}};
  const Result<LoadedModel> model = LoadUrdfString(ArmUrdf(), options);
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->links.size(), 3u);
  EXPECT_EQ(model->links[0].mass, 2.0);
  EXPECT_EQ(model->links[1].mass, 0.5);
  EXPECT_EQ(model->links[2].mass, 0.25);
  EXPECT_EQ(model->mass_properties.mass, 2.75);
  // The forearm frame sits at the elbow, turned a quarter turn about z.
  const Pose& forearm = model->links[1].root_from_link;
  EXPECT_TRUE(forearm.translation.isApprox(Vec3(1, 0, 0), 1e-15));
  EXPECT_TRUE((forearm.rotation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-15));
  // The slider's origin is 1 m along the turned forearm's x (world +y), and it
  // slides 0.5 m along the forearm's y (world -x).
  EXPECT_TRUE(model->links[2].root_from_link.translation.isApprox(Vec3(0.5, 1, 0), 1e-15));
  ASSERT_EQ(model->joints.size(), 2u);
  EXPECT_EQ(model->joints[0].name, "elbow");
  EXPECT_EQ(model->joints[0].type, "revolute");
  EXPECT_EQ(model->joints[0].parent_link, "base");
  EXPECT_EQ(model->joints[0].child_link, "forearm");
  EXPECT_EQ(model->joints[0].position, kPi / 2.0);
  EXPECT_EQ(model->joints[1].position, 0.5);
  // The sphere collision of the forearm is 1 m along its x: at (1, 1, 0).
  const auto& sphere = model->shapes[1].shape.body_from_shape;
  EXPECT_TRUE(sphere.translation.isApprox(Vec3(1, 1, 0), 1e-15));
  EXPECT_EQ(model->warnings.size(), 2u);
}

TEST(UrdfLoaderTest, BadJointPositionsAreRefusedByName) {
  UrdfLoadOptions options;
  options.weld_movable_joints = true;
  options.joint_positions = {{"elbow", 2.5}};
  Result<LoadedModel> model = LoadUrdfString(ArmUrdf(), options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.message(), "joint 'elbow' position 2.5 rad is outside its limits [-1, 2]");
  options.joint_positions = {{"wrist", 0.0}};
  model = LoadUrdfString(ArmUrdf(), options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.message(),
            "joint 'wrist' is not a movable joint of the model; movable: 'elbow', 'slider'");
  // Neither welded nor articulated, the same model is refused.
  options.weld_movable_joints = false;
  options.joint_positions.clear();
  model = LoadUrdfString(ArmUrdf(), options);
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.message().find("joint 'elbow' is revolute"), std::string::npos);
}

// Articulated: each movable joint a joint of the articulation, links with
// their own masses, joint frames in the parent link's frame, limits, and
// the initial positions; planar joints are refused by name.
TEST(UrdfLoaderTest, ArticulatedModelKeepsItsJoints) {
  UrdfLoadOptions options;
  options.articulate = true;
  options.joint_positions = {{"elbow", 0.5}};
  const Result<LoadedModel> model = LoadUrdfString(ArmUrdf(), options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_TRUE(model->articulated);
  std::vector<std::string> warnings;
  const Result<physics::ArticulationDef> def = MakeArticulationDef(*model, &warnings);
  ASSERT_TRUE(def.ok()) << def.message();
  ASSERT_EQ(def->links.size(), 3u);
  EXPECT_EQ(def->links[1].name, "forearm");
  EXPECT_EQ(def->links[0].mass_properties.mass, 2.0);
  EXPECT_EQ(def->links[1].mass_properties.mass, 0.5);
  EXPECT_EQ(def->links[2].mass_properties.mass, 0.25);
  ASSERT_EQ(def->joints.size(), 2u);
  const physics::JointDef& elbow = def->joints[0];
  EXPECT_EQ(elbow.type, physics::JointType::kRevolute);
  EXPECT_EQ(elbow.parent_link, 0);
  EXPECT_EQ(elbow.child_link, 1);
  EXPECT_TRUE(elbow.parent_from_joint.translation.isApprox(Vec3(1, 0, 0), 1e-15));
  EXPECT_EQ(elbow.lower, -1.0);
  EXPECT_EQ(elbow.upper, 2.0);
  EXPECT_EQ(elbow.position, 0.5);
  const physics::JointDef& slider = def->joints[1];
  EXPECT_EQ(slider.type, physics::JointType::kPrismatic);
  // The slider's joint frame in the forearm's frame, whatever the elbow's
  // initial turn.
  EXPECT_TRUE(slider.parent_from_joint.translation.isApprox(Vec3(1, 0, 0), 1e-15));
  EXPECT_TRUE(slider.axis.isApprox(Vec3::UnitY(), 1e-15));
  // The forearm's sphere, in the forearm's frame.
  ASSERT_EQ(def->links[1].shapes.size(), 1u);
  EXPECT_TRUE(def->links[1].shapes[0].body_from_shape.translation.isApprox(Vec3(1, 0, 0), 1e-15));
  EXPECT_TRUE(warnings.empty());

  std::string planar = ArmUrdf();
  planar.replace(planar.find("type=\"prismatic\""), 16, "type=\"planar\"");
  const Result<LoadedModel> refused = LoadUrdfString(planar, options);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("joint 'slider' is planar"), std::string::npos);
}

// A floating joint to 'world' leaves the root free; a movable one keeps
// 'world' as a base without mass, which the articulation fixes.
TEST(UrdfLoaderTest, JointToWorldIsFixedOrFloating) {
  const auto urdf = [](const std::string& type) {
    return "<robot name=\"r\"><link name=\"world\"/><joint name=\"to_world\" type=\"" + type +
           "\"><parent link=\"world\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/>"
           "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
           "<link name=\"b\"><collision><geometry><sphere radius=\"0.1\"/></geometry>"
           "</collision></link></robot>";
  };
  UrdfLoadOptions options;
  options.articulate = true;
  Result<LoadedModel> model = LoadUrdfString(urdf("fixed"), options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_TRUE(model->is_static);
  model = LoadUrdfString(urdf("floating"), options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_FALSE(model->is_static);
  model = LoadUrdfString(urdf("revolute"), options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_FALSE(model->is_static);
  EXPECT_EQ(model->root_link, "world");
  ASSERT_EQ(model->joints.size(), 1u);
  EXPECT_EQ(model->joints[0].type, "revolute");
  std::vector<std::string> warnings;
  const Result<physics::ArticulationDef> def = MakeArticulationDef(*model, &warnings);
  ASSERT_TRUE(def.ok()) << def.message();
  EXPECT_TRUE(def->fixed_base);
  ASSERT_EQ(def->links.size(), 2u);
  EXPECT_EQ(def->links[0].name, "world");
}

}  // namespace
}  // namespace rigid_body_sim::io
