// The articulated scenes in MuJoCo (Debian's libmujoco 2.2.2), with either
// of its explicit integrators: RK4 and semi-implicit Euler. The model is
// written as MJCF from the scene's description (BuildMjcf) and compiled by
// mj_loadXML from a virtual file.
//
// Matched to ours and to Bullet's btMultiBody: gravity 9.81 m/s^2 along -z,
// the scene's time step, joint damping, armature and friction loss 0, no
// joint limits, no self-collision, one thread. Scenes without free bodies
// (chain_30, the arms) have contacts disabled: nothing in them touches.
// arm_push_100's boxes are free bodies with box geoms on a plane, with
// MuJoCo's default soft contacts (condim 3, pyramidal cone), each geom's
// friction the scene's (MuJoCo takes the larger of two geoms' coefficients
// where ours takes their geometric mean: equal in that scene, where all are
// 0.5). MuJoCo has no restitution coefficient; the scene's is 0.
//
// MuJoCo's integrators, as its documentation (Computation > Numerical
// integration; XML reference, option/integrator) describes them: Euler is
// semi-implicit (velocity first, then positions with the new velocity) and
// treats joint damping implicitly, which these models do not have; RK4 is
// the classic fourth-order Runge-Kutta, evaluating the dynamics four times
// per step. Both are explicit in the actuators' forces.
//
// Velocity motors: ours and Bullet's are constraint rows that reach the
// commanded velocity within a step unless the effort limit caps them.
// MuJoCo's actuators are forces, integrated explicitly, so a pure velocity
// servo (force kv (v - qdot)) would let gravity drag a held joint at tau/kv
// without end. Each motor is instead a PD servo on the commanded angle, the
// running sum of the commanded velocities, with the velocity fed forward:
// tau = kp (target - q) + kv (v - qdot), capped at the effort limit
// (forcerange). Its gains: critically damped at a natural frequency of
// kServoBandwidth / dt for the joint's own inertia at the start, well inside
// both integrators' stability bounds. mjENBL_ENERGY stays off, so that the
// timed step does not compute the energy; MechanicalEnergy computes it after
// the step, outside the timing.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine.h"

namespace rigid_body_sim::bench {
namespace {

// rad: the servo's natural frequency times the step.
constexpr double kServoBandwidth = 0.2;
// MuJoCo's pyramidal friction cone with condim 3: two edges per tangent
// direction.
constexpr int kRowsPerContact = 4;
constexpr char kModelFile[] = "bench.xml";

// Geom collision groups: links touch free bodies and the ground, not each
// other (MuJoCo collides two geoms when either's contype meets the other's
// conaffinity).
constexpr char kLinkGeomFilter[] = "contype=\"2\" conaffinity=\"1\"";
constexpr char kWorldGeomFilter[] = "contype=\"1\" conaffinity=\"3\"";

std::string Number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

std::string Triple(const Vec3& v) {
  return Number(v.x()) + " " + Number(v.y()) + " " + Number(v.z());
}

std::string PoseAttributes(const Pose& pose) {
  const Quat& q = pose.rotation;
  return "pos=\"" + Triple(pose.translation) + "\" quat=\"" + Number(q.w()) + " " + Number(q.x()) +
         " " + Number(q.y()) + " " + Number(q.z()) + "\"";
}

std::string Inertial(double mass, const Vec3& center, const Vec3& diagonal) {
  return "<inertial pos=\"" + Triple(center) + "\" mass=\"" + Number(mass) + "\" diaginertia=\"" +
         Triple(diagonal) + "\"/>\n";
}

std::string Friction(const BenchMaterial& material) {
  return "friction=\"" + Number(material.friction) + " 0.005 0.0001\"";
}

// The bodies of articulation `index`: link `link` and, nested, its children.
void AppendLink(const BenchArticulation& articulation, int index, int link, int first_joint,
                std::ostringstream* xml) {
  const BenchLink& def = articulation.links[link];
  if (link == 0) {
    *xml << "<body name=\"a" << index << "_link0\" " << PoseAttributes(articulation.world_from_base)
         << ">\n";
  } else {
    const BenchJoint& joint = articulation.joints[link - 1];
    *xml << "<body name=\"a" << index << "_link" << link << "\" pos=\""
         << Triple(joint.parent_offset) << "\">\n"
         << "<joint name=\"joint_" << first_joint + link - 1 << "\" type=\"hinge\" axis=\""
         << Triple(joint.axis) << "\" limited=\"false\" damping=\"0\" armature=\"0\"/>\n";
  }
  *xml << Inertial(def.mass, def.center_of_mass, def.inertia_diagonal);
  if (def.has_box) {
    *xml << "<geom type=\"box\" size=\"" << Triple(0.5 * def.box_size) << "\" pos=\""
         << Triple(def.center_of_mass) << "\" " << kLinkGeomFilter << " " << Friction(def.material)
         << "/>\n";
  }
  for (std::size_t j = 0; j < articulation.joints.size(); ++j) {
    if (articulation.joints[j].parent == link) {
      AppendLink(articulation, index, static_cast<int>(j) + 1, first_joint, xml);
    }
  }
  *xml << "</body>\n";
}

void AppendFreeBody(const BenchBody& body, int index, std::ostringstream* xml) {
  *xml << "<body name=\"body_" << index << "\" " << PoseAttributes(body.world_from_body) << ">\n"
       << "<joint name=\"free_" << index << "\" type=\"free\"/>\n";
  if (body.shape == BenchBody::Shape::kBox) {
    const Vec3 squared = body.box_size.cwiseProduct(body.box_size);
    const Vec3 inertia =
        body.mass / 12.0 *
        Vec3(squared.y() + squared.z(), squared.x() + squared.z(), squared.x() + squared.y());
    *xml << Inertial(body.mass, Vec3::Zero(), inertia) << "<geom type=\"box\" size=\""
         << Triple(0.5 * body.box_size) << "\" ";
  } else {
    const double r = body.sphere_radius;
    *xml << Inertial(body.mass, Vec3::Zero(), Vec3::Constant(0.4 * body.mass * r * r))
         << "<geom type=\"sphere\" size=\"" << Number(r) << "\" ";
  }
  *xml << kWorldGeomFilter << " " << Friction(body.material) << "/>\n</body>\n";
}

// The scene as MJCF; joints are named joint_<k>, k numbered over all the
// articulations (Engine), free bodies body_<i>, motors motor_<k>.
std::string BuildMjcf(const Scene& scene, bool rk4) {
  const bool contacts = !scene.bodies.empty();
  std::ostringstream xml;
  xml << "<mujoco model=\"" << scene.name << "\">\n"
      << "<compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      << "<option timestep=\"" << Number(scene.time_step) << "\" integrator=\""
      << (rk4 ? "RK4" : "Euler") << "\" gravity=\"0 0 " << Number(-kGravity) << "\">\n"
      << "<flag contact=\"" << (contacts ? "enable" : "disable") << "\"/>\n</option>\n";
  if (contacts) {
    // Room for every box on the ground (4 points each) and a few between
    // boxes, 4 rows per point.
    const int points = 12 * static_cast<int>(scene.bodies.size()) + 100;
    xml << "<size nconmax=\"" << points << "\" njmax=\"" << kRowsPerContact * points << "\"/>\n";
  }
  xml << "<worldbody>\n";
  if (contacts) {
    xml << "<geom name=\"ground\" type=\"plane\" size=\"0 0 1\" "
        << PoseAttributes(scene.world_from_ground) << " " << kWorldGeomFilter << " "
        << Friction(scene.ground_material) << "/>\n";
  }
  int first_joint = 0;
  for (std::size_t a = 0; a < scene.articulations.size(); ++a) {
    AppendLink(scene.articulations[a], static_cast<int>(a), 0, first_joint, &xml);
    first_joint += static_cast<int>(scene.articulations[a].joints.size());
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    AppendFreeBody(scene.bodies[i], static_cast<int>(i), &xml);
  }
  xml << "</worldbody>\n<actuator>\n";
  first_joint = 0;
  for (const BenchArticulation& articulation : scene.articulations) {
    for (std::size_t j = 0; j < articulation.joints.size(); ++j) {
      if (j < articulation.motors.size() && !articulation.motors[j].empty()) {
        // gain and bias are set once the model is compiled (MujocoEngine).
        const std::string limit = Number(articulation.joints[j].effort_limit);
        xml << "<general name=\"motor_" << first_joint + j << "\" joint=\"joint_" << first_joint + j
            << "\" gaintype=\"fixed\" biastype=\"affine\" "
            << "forcelimited=\"true\" forcerange=\"-" << limit << " " << limit << "\"/>\n";
      }
    }
    first_joint += static_cast<int>(articulation.joints.size());
  }
  xml << "</actuator>\n</mujoco>\n";
  return xml.str();
}

// Compiles `xml` from a virtual file; throws with MuJoCo's message.
mjModel* LoadModel(const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), kModelFile, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("mujoco: cannot make the virtual model file");
  }
  std::memcpy(vfs->filedata[vfs->nfile - 1], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* model = mj_loadXML(kModelFile, vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  if (model == nullptr) throw std::runtime_error(std::string("mujoco: ") + error);
  return model;
}

struct MujocoJoint {
  int qpos = 0;    // address in qpos
  int dof = 0;     // address in qvel
  int parent = 0;  // body ids
  int child = 0;
  Vec3 parent_offset;     // m, parent body frame: the anchor
  int actuator = -1;      // its motor, if any
  double kp = 0.0;        // N m / rad
  double kv = 0.0;        // N m s / rad
  double target = 0.0;    // rad, the commanded angle
  double velocity = 0.0;  // rad/s, the command
};

class MujocoEngine : public Engine {
 public:
  MujocoEngine(const Scene& scene, bool rk4)
      : name_(rk4 ? "mujoco_rk4" : "mujoco_euler"), time_step_(scene.time_step) {
    model_ = LoadModel(BuildMjcf(scene, rk4));
    data_ = mj_makeData(model_);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const std::string body = "body_" + std::to_string(i);
      bodies_.push_back(mj_name2id(model_, mjOBJ_BODY, body.c_str()));
    }
    int k = 0;
    for (const BenchArticulation& articulation : scene.articulations) {
      for (std::size_t j = 0; j < articulation.joints.size(); ++j, ++k) {
        AddJoint(articulation, static_cast<int>(j), k);
      }
    }
    mj_forward(model_, data_);
    SetServoGains();
    dirty_ = false;
  }

  ~MujocoEngine() override {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }

  std::string name() const override { return name_; }

  void Step() override {
    for (MujocoJoint& joint : joints_) {
      if (joint.actuator < 0) continue;
      // The angle at the end of this step, the velocity fed forward.
      joint.target += joint.velocity * time_step_;
      data_->ctrl[joint.actuator] = joint.target + joint.kv / joint.kp * joint.velocity;
    }
    mj_step(model_, data_);
    dirty_ = true;
  }

  StageTimes LastStageTimes() const override {
    StageTimes times;
    times.solver_points = static_cast<std::size_t>(data_->ncon);
    times.point_iterations = times.solver_points * static_cast<std::size_t>(data_->solver_iter);
    return times;
  }

  Vec3 Position(int index) const override {
    const mjtNum* q = data_->qpos + FreeJoint(index, model_->jnt_qposadr);
    return Vec3(q[0], q[1], q[2]);
  }
  // A free joint's first three velocities are its body's, world frame.
  Vec3 LinearVelocity(int index) const override {
    const mjtNum* v = data_->qvel + FreeJoint(index, model_->jnt_dofadr);
    return Vec3(v[0], v[1], v[2]);
  }

  double KineticEnergy() const override;
  double MechanicalEnergy() const override;

  double MaxPenetration() const override {
    double depth = 0.0;
    for (int i = 0; i < data_->ncon; ++i) depth = std::max(depth, -data_->contact[i].dist);
    return depth;
  }

  int RowsPerPoint() const override { return kRowsPerContact; }
  bool AllMovingBodiesAwake() const override { return true; }  // MuJoCo 2.2 never sleeps
  double JointAnchorSeparation() const override;
  double JointPosition(int joint) const override { return data_->qpos[joints_[joint].qpos]; }

  void SetMotorVelocity(int joint, double velocity) override { joints_[joint].velocity = velocity; }

 private:
  void AddJoint(const BenchArticulation& articulation, int j, int k);
  void SetServoGains();
  // The kinematics and velocities of the state after the last step.
  void Refresh() const;
  int FreeJoint(int index, const int* address) const {
    return address[model_->body_jntadr[bodies_[index]]];
  }

  std::string name_;
  double time_step_;  // s
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<int> bodies_;  // the scene's free bodies' ids
  std::vector<MujocoJoint> joints_;
  // mj_step leaves the kinematics of the positions it started from.
  mutable bool dirty_ = true;
};

void MujocoEngine::AddJoint(const BenchArticulation& articulation, int j, int k) {
  const std::string name = "joint_" + std::to_string(k);
  const int id = mj_name2id(model_, mjOBJ_JOINT, name.c_str());
  MujocoJoint joint;
  joint.qpos = model_->jnt_qposadr[id];
  joint.dof = model_->jnt_dofadr[id];
  joint.child = model_->jnt_bodyid[id];
  joint.parent = model_->body_parentid[joint.child];
  joint.parent_offset = articulation.joints[j].parent_offset;
  joint.target = articulation.joints[j].position;
  data_->qpos[joint.qpos] = joint.target;
  const std::string motor = "motor_" + std::to_string(k);
  joint.actuator = mj_name2id(model_, mjOBJ_ACTUATOR, motor.c_str());
  joints_.push_back(joint);
}

// Critically damped at kServoBandwidth / dt for the joint's diagonal entry of
// the joint-space inertia at the start (qM, after mj_forward).
void MujocoEngine::SetServoGains() {
  for (MujocoJoint& joint : joints_) {
    if (joint.actuator < 0) continue;
    const double inertia = data_->qM[model_->dof_Madr[joint.dof]];
    const double omega = kServoBandwidth / time_step_;
    joint.kp = inertia * omega * omega;
    joint.kv = 2.0 * inertia * omega;
    mjtNum* gain = model_->actuator_gainprm + mjNGAIN * joint.actuator;
    mjtNum* bias = model_->actuator_biasprm + mjNBIAS * joint.actuator;
    gain[0] = joint.kp;
    bias[0] = 0.0;
    bias[1] = -joint.kp;
    bias[2] = -joint.kv;
    data_->ctrl[joint.actuator] = joint.target;
  }
}

void MujocoEngine::Refresh() const {
  if (!dirty_) return;
  mj_kinematics(model_, data_);
  mj_comPos(model_, data_);
  mj_comVel(model_, data_);
  dirty_ = false;
}

// T = 1/2 m v^2 + 1/2 omega.I omega per free body; a free joint's angular
// velocity is in its body's frame, the inertia's principal frame here.
double MujocoEngine::KineticEnergy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const mjtNum* v = data_->qvel + FreeJoint(static_cast<int>(i), model_->jnt_dofadr);
    const mjtNum* inertia = model_->body_inertia + 3 * bodies_[i];
    const double mass = model_->body_mass[bodies_[i]];
    energy +=
        0.5 * mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
        0.5 * (inertia[0] * v[3] * v[3] + inertia[1] * v[4] * v[4] + inertia[2] * v[5] * v[5]);
  }
  return energy;
}

// Per body not welded to the world: 1/2 m v^2 + 1/2 omega.I omega in its
// inertial frame (mj_objectVelocity on the velocities of mj_comVel) plus
// m g z of its centre of mass; NaN once MuJoCo found a bad number, as it
// then resets the state by itself.
double MujocoEngine::MechanicalEnergy() const {
  for (const int warning : {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC}) {
    if (data_->warning[warning].number > 0) return std::numeric_limits<double>::quiet_NaN();
  }
  Refresh();
  double energy = 0.0;
  for (int b = 1; b < model_->nbody; ++b) {
    if (model_->body_weldid[b] == 0) continue;
    mjtNum velocity[6];  // angular, then linear; the body's inertial frame
    mj_objectVelocity(model_, data_, mjOBJ_BODY, b, velocity, /*flg_local=*/1);
    const double mass = model_->body_mass[b];
    const mjtNum* inertia = model_->body_inertia + 3 * b;
    energy +=
        0.5 * mass *
            (velocity[3] * velocity[3] + velocity[4] * velocity[4] + velocity[5] * velocity[5]) +
        0.5 * (inertia[0] * velocity[0] * velocity[0] + inertia[1] * velocity[1] * velocity[1] +
               inertia[2] * velocity[2] * velocity[2]) +
        mass * kGravity * data_->xipos[3 * b + 2];
  }
  return energy;
}

double MujocoEngine::JointAnchorSeparation() const {
  Refresh();
  double separation = 0.0;
  for (const MujocoJoint& joint : joints_) {
    const mjtNum* origin = data_->xpos + 3 * joint.parent;
    const mjtNum* rotation = data_->xmat + 9 * joint.parent;  // row-major
    Vec3 gap;
    for (int r = 0; r < 3; ++r) {
      gap[r] = origin[r] + rotation[3 * r] * joint.parent_offset.x() +
               rotation[3 * r + 1] * joint.parent_offset.y() +
               rotation[3 * r + 2] * joint.parent_offset.z() - data_->xpos[3 * joint.child + r];
    }
    separation = std::max(separation, gap.norm());
  }
  return separation;
}

}  // namespace

std::unique_ptr<Engine> MakeMujocoEngine(const Scene& scene, bool rk4) {
  return std::make_unique<MujocoEngine>(scene, rk4);
}

}  // namespace rigid_body_sim::bench
