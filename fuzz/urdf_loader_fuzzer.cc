// libFuzzer harness: any bytes as a URDF document. The loader must answer
// with a model or a message, never crash, hang or leak; a model it accepts
// must be one the world accepts too. Mesh URIs are refused by the resolver:
// meshes have their own harness (mesh_parser_fuzzer.cc).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using rigid_body_sim::physics::Result;
  rigid_body_sim::io::UrdfLoadOptions options;
  options.max_links = 200;
  options.resolver = [](const std::string& uri) -> Result<std::string> {
    return Result<std::string>::Error("no meshes in this harness: " + uri);
  };
  const std::string xml(reinterpret_cast<const char*>(data), size);
  const Result<rigid_body_sim::io::LoadedModel> model =
      rigid_body_sim::io::LoadUrdfString(xml, options);
  if (!model.ok()) {
    if (model.message().empty()) std::abort();  // a refusal must say why
    return 0;
  }
  rigid_body_sim::physics::BodyDef def;
  def.is_static = model->is_static;
  def.mass_properties = model->mass_properties;
  for (const rigid_body_sim::io::LoadedShape& shape : model->shapes)
    def.shapes.push_back(shape.shape);
  rigid_body_sim::physics::World world;
  const auto body = world.CreateBody(def);
  if (!body.ok()) std::abort();  // the loader let through what the world refuses
  for (int i = 0; i < 3; ++i) world.Step();
  if (!world.GetBody(*body).HasFiniteState()) std::abort();
  return 0;
}
