// The node's ROS-free model logic: names, materials, frames and the registry.
#include "rigid_body_sim/node/model_registry.h"

#include <gtest/gtest.h>

#include <memory>

namespace rigid_body_sim::node {
namespace {

using physics::Pose;
using physics::Quat;
using physics::Vec3;

io::LoadedModel TwoLinkModel() {
  io::LoadedModel model;
  model.name = "thing";
  model.root_link = "base";
  model.mass_properties.mass = 2.0;
  model.mass_properties.inertia_about_com = physics::Mat3::Identity();
  io::LoadedShape base;
  base.shape.geometry = physics::Sphere{0.1};
  base.link_name = "base";
  io::LoadedShape arm;
  arm.shape.geometry = physics::Sphere{0.05};
  arm.shape.material.friction = 0.9;
  arm.friction_from_urdf = true;
  arm.link_name = "arm";
  model.shapes = {base, arm};
  model.links = {{"base", Pose::Identity(), 0.0, {}},
                 {"arm", Pose{Vec3(1, 0, 0), Quat::Identity()}, 0.0, {}}};
  return model;
}

TEST(ModelRegistryTest, NamesFollowThePattern) {
  EXPECT_TRUE(ValidateModelName("box_1").ok());
  EXPECT_TRUE(ValidateModelName("_x").ok());
  EXPECT_EQ(ValidateModelName("").message(), "model name is empty");
  EXPECT_NE(ValidateModelName("a-b").message().find("bad character '-' at position 1"),
            std::string::npos);
  EXPECT_NE(ValidateModelName("1a").message().find("bad character '1' at position 0"),
            std::string::npos);
  EXPECT_NE(ValidateModelName("a/b").message().find("bad character '/'"), std::string::npos);
  EXPECT_NE(ValidateModelName("ground").message().find("reserved"), std::string::npos);
}

TEST(ModelRegistryTest, MaterialsComeFromSpecThenUrdfThenDefaults) {
  const io::LoadedModel model = TwoLinkModel();
  ModelSpec spec;
  MaterialDefaults defaults{0.4, 0.3};
  auto def = MakeBodyDef(model, spec, defaults);
  ASSERT_TRUE(def.ok());
  EXPECT_EQ(def->shapes[0].material.friction, 0.4);
  EXPECT_EQ(def->shapes[1].material.friction, 0.9);
  EXPECT_EQ(def->shapes[0].material.restitution, 0.3);
  spec.friction = 0.1;
  spec.restitution = 0.7;
  def = MakeBodyDef(model, spec, defaults);
  ASSERT_TRUE(def.ok());
  EXPECT_EQ(def->shapes[1].material.friction, 0.1);
  EXPECT_EQ(def->shapes[1].material.restitution, 0.7);
  spec.restitution = 1.5;
  EXPECT_EQ(MakeBodyDef(model, spec, defaults).message(), "restitution 1.5 is outside [0, 1]");
}

TEST(ModelRegistryTest, StaticBodiesHaveNoVelocity) {
  ModelSpec spec;
  spec.is_static = true;
  spec.root_state.linear_velocity = Vec3(1, 0, 0);
  const auto def = MakeBodyDef(TwoLinkModel(), spec, {});
  ASSERT_TRUE(def.ok());
  EXPECT_TRUE(def->is_static);
  EXPECT_EQ(def->linear_velocity, Vec3::Zero());
}

TEST(ModelRegistryTest, LinkVelocityIsTheRigidBodyFieldAtItsOrigin) {
  // Root at the origin turned a quarter about z, spinning at 2 rad/s about z;
  // the link 1 m along the root's x sits at world (0, 1, 0) and moves at
  // w x r = (0, 0, 2) x (0, 1, 0) = (-2, 0, 0) plus the root's (0, 0, 3).
  FrameState root;
  root.world_from_frame.rotation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  root.linear_velocity = Vec3(0, 0, 3);
  root.angular_velocity = Vec3(0, 0, 2);
  const Pose root_from_link{Vec3(1, 0, 0), Quat::Identity()};
  const FrameState link = LinkStateFromRoot(root, root_from_link);
  EXPECT_TRUE(link.world_from_frame.translation.isApprox(Vec3(0, 1, 0), 1e-15));
  EXPECT_TRUE(link.linear_velocity.isApprox(Vec3(-2, 0, 3), 1e-15));
  const FrameState back = RootStateFromLink(link, root_from_link);
  EXPECT_LT(back.world_from_frame.translation.norm(), 1e-15);
  EXPECT_TRUE(back.linear_velocity.isApprox(root.linear_velocity, 1e-15));
  EXPECT_NEAR(std::abs(back.world_from_frame.rotation.dot(root.world_from_frame.rotation)), 1.0,
              1e-15);
}

TEST(ModelRegistryTest, RegistryResolvesModelsLinksAndBodies) {
  const io::LoadedModel loaded = TwoLinkModel();
  ModelRegistry registry;
  Model model;
  model.name = "thing";
  model.body = physics::BodyId{3, 7};
  model.links = loaded.links;
  model.bodies = {model.body};
  model.body_shape_links = {{"base", "arm"}};
  ASSERT_TRUE(registry.Add(model).ok());
  EXPECT_EQ(registry.Add(model).message(), "a model named 'thing' already exists");
  auto frame = registry.ResolveFrame("thing");
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->link->link_name, "base");
  frame = registry.ResolveFrame("thing/arm");
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->link->root_from_link.translation, Vec3(1, 0, 0));
  EXPECT_EQ(registry.ResolveFrame("thing/leg").message(), "model 'thing' has no link named 'leg'");
  EXPECT_EQ(registry.ResolveFrame("other/arm").message(), "no model named 'other'");
  EXPECT_EQ(registry.ShapeFrame(physics::BodyId{3, 7}, 1), "thing/arm");
  EXPECT_EQ(registry.ShapeFrame(physics::BodyId{3, 8}, 0), "");
  EXPECT_TRUE(registry.Remove("thing"));
  EXPECT_FALSE(registry.Remove("thing"));
  EXPECT_EQ(registry.FindByBody(physics::BodyId{3, 7}), nullptr);
  EXPECT_EQ(registry.size(), 0u);
}

}  // namespace
}  // namespace rigid_body_sim::node
