// Static meshes through the io layer: the helper's triangles are the
// in-process ones exactly; a static model's mesh keeps its triangles, a
// moving one's becomes its hull; <mesh_collision> picks either and is
// checked.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <variant>

#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::Vec3;

const std::string kUrdfDir = RBS_URDF_DIR;

MeshProcessLimits HelperLimits() {
  MeshProcessLimits limits;
  limits.helper_path = RBS_MESH_HELPER;
  return limits;
}

Result<std::string> ResolvePackage(const std::string& uri) {
  const std::string prefix = "package://rigid_body_sim/urdf/";
  if (uri.rfind(prefix, 0) == 0) return kUrdfDir + "/" + uri.substr(prefix.size());
  return ResolveFileUri(uri);
}

UrdfLoadOptions OutOfProcessOptions() {
  UrdfLoadOptions options;
  options.resolver = ResolvePackage;
  const MeshProcessLimits limits = HelperLimits();
  options.mesh_hull_loader = [limits](const std::string& path, const Vec3& scale,
                                      const HullOptions& hull) {
    return CachedMeshHull(path, scale, hull, limits);
  };
  options.mesh_triangles_loader = [limits](const std::string& path, const Vec3& scale) {
    return CachedMeshTriangles(path, scale, limits);
  };
  return options;
}

std::string MeshModel(bool fixed_to_world, const std::string& gazebo) {
  std::string xml = "<robot name='m'>";
  if (fixed_to_world) {
    xml +=
        "<link name='world'/><joint name='j' type='fixed'><parent link='world'/>"
        "<child link='base'/></joint>";
  }
  xml +=
      "<link name='base'><collision name='shell'><geometry><mesh "
      "filename='package://rigid_body_sim/urdf/meshes/bin.stl'/></geometry></collision>"
      "<collision name='lid'><geometry><mesh "
      "filename='package://rigid_body_sim/urdf/meshes/bin.stl' scale='1 1 0.1'/>"
      "</geometry></collision></link>" +
      gazebo + "</robot>";
  return xml;
}

TEST(StaticMeshIoTest, HelperTrianglesAreTheInProcessTrianglesExactly) {
  const std::string path = kUrdfDir + "/meshes/bin.stl";
  const Vec3 scale(2.0, 1.0, 0.5);
  const Result<physics::TriangleMesh> remote =
      LoadMeshTrianglesOutOfProcess(path, scale, HelperLimits());
  ASSERT_TRUE(remote.ok()) << remote.message();
  const Result<physics::TriangleMesh> local = LoadMesh(path, scale);
  ASSERT_TRUE(local.ok()) << local.message();
  EXPECT_EQ(remote->vertices, local->vertices);
  EXPECT_EQ(remote->triangles, local->triangles);
  EXPECT_EQ(remote->triangles.size(), 28u);
}

// The helper sends a static mesh's triangles as raw doubles and indices
// after a header line: the parse gives back every bit, and any byte count,
// index or coordinate that does not fit is refused.
TEST(StaticMeshIoTest, BinaryTrianglesReplyRoundTripsAndIsChecked) {
  physics::TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1.0 / 3.0, 0, 1e-300), Vec3(0, 0.1, -7.25)};
  mesh.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(2, 1, 0)};
  const std::string reply = FormatTrianglesReply(mesh);
  EXPECT_EQ(reply.rfind("triangles-binary 3 2\n", 0), 0u);
  EXPECT_EQ(reply.size(), std::string("triangles-binary 3 2\n").size() + 3 * 24 + 2 * 12);
  const Result<physics::TriangleMesh> back = ParseTrianglesReply(reply);
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back->vertices, mesh.vertices);
  EXPECT_EQ(back->triangles, mesh.triangles);
  EXPECT_NE(ParseTrianglesReply(reply.substr(0, reply.size() - 1)).message().find("expected"),
            std::string::npos);
  std::string bad_index = reply;
  bad_index[bad_index.size() - 4] = 3;  // the last index, little end first
  EXPECT_NE(ParseTrianglesReply(bad_index).message().find("vertex index outside"),
            std::string::npos);
  physics::TriangleMesh not_finite = mesh;
  not_finite.vertices[1].y() = std::numeric_limits<double>::infinity();
  EXPECT_NE(ParseTrianglesReply(FormatTrianglesReply(not_finite)).message().find("not finite"),
            std::string::npos);
}

// A binary STL of n triangles is 84 + 50 n bytes with n in its header: the
// helper refuses one above ~max_mesh_triangles before assimp reads it, so
// the refusal comes at once and names the limit.
TEST(StaticMeshIoTest, TriangleLimitIsMetBeforeTheFileIsRead) {
  const std::string path = ::testing::TempDir() + "/rbs_too_many_triangles.stl";
  const std::uint32_t count = 50000;
  {
    std::ofstream file(path, std::ios::binary);
    file << std::string(80, ' ');
    file.write(reinterpret_cast<const char*>(&count), sizeof(count));
    for (std::uint32_t i = 0; i < count; ++i) {
      const float x = static_cast<float>(i % 250);
      const float y = static_cast<float>(i / 250);
      const float record[12] = {0, 0, 1, x, y, 0, x + 1, y, 0, x, y + 1, 0};
      file.write(reinterpret_cast<const char*>(record), sizeof(record));
      file.write("\0\0", 2);
    }
  }
  MeshProcessLimits limits = HelperLimits();
  limits.max_triangles = count - 1;
  const auto start = std::chrono::steady_clock::now();
  const Result<physics::TriangleMesh> refused =
      LoadMeshTrianglesOutOfProcess(path, Vec3::Ones(), limits);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("has 50000 triangles, more than the limit of 49999"),
            std::string::npos)
      << refused.message();
  EXPECT_NE(refused.message().find("~max_mesh_triangles"), std::string::npos);
  EXPECT_LT(seconds, 1.0);
  limits.max_triangles = count;
  const Result<physics::TriangleMesh> loaded =
      LoadMeshTrianglesOutOfProcess(path, Vec3::Ones(), limits);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->triangles.size(), count);
  std::remove(path.c_str());
}

// A model spawned static needs no mass: its triangle meshes have no volume
// to give it one, and no <inertial> is asked for (a bin built of parts).
TEST(StaticMeshIoTest, SpawnedStaticMeshModelNeedsNoInertial) {
  for (const bool out_of_process : {false, true}) {
    UrdfLoadOptions options = out_of_process ? OutOfProcessOptions() : UrdfLoadOptions();
    options.resolver = ResolvePackage;
    const Result<LoadedModel> moving = LoadUrdfString(MeshModel(false, ""), options);
    options.spawn_static = true;
    const Result<LoadedModel> spawned_static = LoadUrdfString(MeshModel(false, ""), options);
    ASSERT_TRUE(spawned_static.ok()) << spawned_static.message();
    EXPECT_EQ(spawned_static->shapes.size(), 2u);
    for (const LoadedShape& shape : spawned_static->shapes) {
      EXPECT_TRUE(std::holds_alternative<physics::StaticMesh>(shape.shape.geometry));
    }
    // Moving, the same model is its meshes' hulls, with their volume's mass.
    ASSERT_TRUE(moving.ok()) << moving.message();
    EXPECT_GT(moving->mass_properties.mass, 0.0);
  }
}

TEST(StaticMeshIoTest, TrianglesReplyIsChecked) {
  EXPECT_EQ(ParseTrianglesReply("error boom\n").message(), "boom");
  EXPECT_FALSE(ParseTrianglesReply("triangles 3 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nt 0 1 3\n").ok());
  EXPECT_NE(ParseTrianglesReply("triangles 3 1\nv 0 0 0\nv 1 0 nan\nv 0 1 0\nt 0 1 2\n")
                .message()
                .find("not a finite number"),
            std::string::npos);
  EXPECT_NE(ParseTrianglesReply("triangles 3 99999999999\n").message().find("outside"),
            std::string::npos);
  const Result<physics::TriangleMesh> good =
      ParseTrianglesReply("triangles 3 1\nv 0x0p+0 0 0\nv 1 0 0\nv 0 1 0\nt 0 1 2\n");
  ASSERT_TRUE(good.ok()) << good.message();
  EXPECT_EQ(good->triangles.front(), Eigen::Vector3i(0, 1, 2));
}

TEST(StaticMeshIoTest, StaticModelsKeepTriangles) {
  for (const bool out_of_process : {false, true}) {
    UrdfLoadOptions options = out_of_process ? OutOfProcessOptions() : UrdfLoadOptions();
    options.resolver = ResolvePackage;
    const Result<LoadedModel> fixed = LoadUrdfString(MeshModel(true, ""), options);
    ASSERT_TRUE(fixed.ok()) << fixed.message();
    ASSERT_EQ(fixed->shapes.size(), 2u);
    const auto* mesh = std::get_if<physics::StaticMesh>(&fixed->shapes[0].shape.geometry);
    ASSERT_NE(mesh, nullptr);
    EXPECT_EQ(mesh->mesh->triangles().size(), 28u);
    EXPECT_NEAR(mesh->mesh->upper().z(), 0.2, 1e-7);
    // The link mass is the bins' material: outer box less the cavity, for
    // the shell and for the lid (the shell at a tenth of its height).
    const double shell = 0.4 * 0.3 * 0.2 - 0.39 * 0.29 * 0.195;
    const double lid = 0.4 * 0.3 * 0.02 - 0.39 * 0.29 * 0.0195;
    EXPECT_NEAR(fixed->links[0].mass, 1000.0 * (shell + lid), 1e-4);

    options.spawn_static = true;
    const Result<LoadedModel> spawned = LoadUrdfString(MeshModel(false, ""), options);
    ASSERT_TRUE(spawned.ok()) << spawned.message();
    EXPECT_TRUE(std::holds_alternative<physics::StaticMesh>(spawned->shapes[1].shape.geometry));
  }
}

// An arm fixed to the world (a UR5's habit) moves below its movable joint,
// so when articulated its meshes collide as hulls or pieces, which a moving
// link can carry: triangles were refused by the world for every published
// UR description. Welded, the whole model is static and keeps triangles.
TEST(StaticMeshIoTest, ArticulatedModelFixedToTheWorldHasNoTriangles) {
  std::string xml = MeshModel(true, "");
  xml.replace(xml.find("</robot>"), std::string::npos,
              "<link name='arm'><inertial><mass value='1'/><inertia ixx='0.1' iyy='0.1' "
              "izz='0.1' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry><box "
              "size='0.1 0.1 0.5'/></geometry></collision></link><joint name='shoulder' "
              "type='continuous'><parent link='base'/><child link='arm'/><origin "
              "xyz='0 0 0.3'/><axis xyz='0 0 1'/></joint></robot>");
  UrdfLoadOptions options = OutOfProcessOptions();
  options.resolver = ResolvePackage;
  options.articulate = true;
  const Result<LoadedModel> articulated = LoadUrdfString(xml, options);
  ASSERT_TRUE(articulated.ok()) << articulated.message();
  for (const LoadedShape& shape : articulated->shapes) {
    EXPECT_FALSE(std::holds_alternative<physics::StaticMesh>(shape.shape.geometry))
        << shape.link_name;
  }
  const Result<physics::ArticulationDef> def = MakeArticulationDef(*articulated, nullptr);
  ASSERT_TRUE(def.ok()) << def.message();
  EXPECT_TRUE(def->fixed_base);
  physics::World world;
  const Result<physics::ArticulationId> created = world.CreateArticulation(*def);
  EXPECT_TRUE(created.ok()) << created.message();

  options.articulate = false;
  options.weld_movable_joints = true;
  const Result<LoadedModel> welded = LoadUrdfString(xml, options);
  ASSERT_TRUE(welded.ok()) << welded.message();
  EXPECT_TRUE(std::holds_alternative<physics::StaticMesh>(welded->shapes[0].shape.geometry));
}

TEST(StaticMeshIoTest, MeshCollisionPicksTrianglesOrHull) {
  UrdfLoadOptions options = OutOfProcessOptions();
  const Result<LoadedModel> moving = LoadUrdfString(MeshModel(false, ""), options);
  ASSERT_TRUE(moving.ok()) << moving.message();
  EXPECT_TRUE(std::holds_alternative<std::shared_ptr<const physics::ConvexPolyhedron>>(
      moving->shapes[0].shape.geometry));

  // A static model's link asks for hulls, one collision back for triangles.
  const std::string gazebo =
      "<gazebo reference='base'><mesh_collision> hull </mesh_collision>"
      "<collision name='lid'><mesh_collision>triangles</mesh_collision></collision></gazebo>";
  const Result<LoadedModel> mixed = LoadUrdfString(MeshModel(true, gazebo), options);
  ASSERT_TRUE(mixed.ok()) << mixed.message();
  EXPECT_TRUE(std::holds_alternative<std::shared_ptr<const physics::ConvexPolyhedron>>(
      mixed->shapes[0].shape.geometry));
  EXPECT_TRUE(std::holds_alternative<physics::StaticMesh>(mixed->shapes[1].shape.geometry));

  const Result<LoadedModel> refused =
      LoadUrdfString(MeshModel(false,
                               "<gazebo reference='base'><mesh_collision>triangles</mesh_collision>"
                               "</gazebo>"),
                     options);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("link 'base' <collision> 'shell': <mesh_collision> "
                                   "'triangles' needs a static model"),
            std::string::npos)
      << refused.message();

  const Result<LoadedModel> unknown =
      LoadUrdfString(MeshModel(true,
                               "<gazebo reference='base'><mesh_collision>voxels</mesh_collision>"
                               "</gazebo>"),
                     options);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("<gazebo reference='base'> <mesh_collision> value 'voxels' "
                                   "is not one of 'triangles', 'hull'"),
            std::string::npos)
      << unknown.message();
  const Result<LoadedModel> unnamed =
      LoadUrdfString(MeshModel(true,
                               "<gazebo reference='base'><collision><mesh_collision>hull"
                               "</mesh_collision></collision></gazebo>"),
                     options);
  ASSERT_FALSE(unnamed.ok());
  EXPECT_NE(unnamed.message().find("needs a name"), std::string::npos) << unnamed.message();
}

}  // namespace
}  // namespace rigid_body_sim::io
