// The parts of a URDF document that the loader reads itself, beside
// urdfdom, and the capture of urdfdom's messages (urdf_loader.cc).
#ifndef RIGID_BODY_SIM_IO_URDF_ELEMENTS_H_
#define RIGID_BODY_SIM_IO_URDF_ELEMENTS_H_

#include <cmath>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_model/model.h>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

inline std::string Quoted(const std::string& text) { return "'" + text + "'"; }

inline bool PositiveFinite(double value) { return std::isfinite(value) && value > 0.0; }

// urdfdom reports why it rejects a document through console_bridge. While a
// document is parsed, its messages are collected here so they can go into
// the returned error instead of the process log. The output handler is
// global, so parses are serialised.
//
// Muted, console_bridge formats nothing: urdfdom hands some text from the
// document to printf as the format itself (a bad <color rgba>, for one), so
// a '%' in the document would be read as conversions with no arguments.
class ConsoleCapture : public console_bridge::OutputHandler {
 public:
  enum class Mode { kCapture, kMuted };
  explicit ConsoleCapture(Mode mode) : lock_(Mutex()), level_(console_bridge::getLogLevel()) {
    console_bridge::useOutputHandler(this);
    if (mode == Mode::kMuted) console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  }
  ~ConsoleCapture() override {
    console_bridge::setLogLevel(level_);
    console_bridge::restorePreviousOutputHandler();
  }
  ConsoleCapture(const ConsoleCapture&) = delete;
  ConsoleCapture& operator=(const ConsoleCapture&) = delete;

  void log(const std::string& text, console_bridge::LogLevel level, const char* /*filename*/,
           int /*line*/) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_WARN) return;
    if (!text_.empty()) text_ += "; ";
    text_ += text;
  }
  const std::string& text() const { return text_; }

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  std::lock_guard<std::mutex> lock_;
  console_bridge::LogLevel level_;
  std::string text_;
};

physics::Pose ToPose(const urdf::Pose& pose);

const char* JointTypeName(int type);

// Friction coefficients from <gazebo reference="LINK"><mu1>, which urdfdom
// does not read, so the XML is walked directly.
physics::Result<std::map<std::string, double>> ReadGazeboFriction(const TiXmlElement& robot);

// Writes ixy, ixz and iyz = 0 into every <inertia> that gives ixx, iyy and
// izz but leaves some of them out, as Bullet reads such a tensor (urdfdom
// would hand back a zero tensor); returns the names of the links changed.
std::vector<std::string> FillOmittedProductsOfInertia(TiXmlElement* robot);

// A link's <inertial> as read, in the link frame, and what reading it changed.
struct InertialReading {
  physics::MassProperties in_link;  // mass 0: a massless link
  std::string warning;              // empty, or what was inferred or adjusted
};

// The link's <inertial> in the link frame, checked: finite, mass >= 0 and
// moments about the axes (ixx, iyy, izz) >= 0. Habits of published
// descriptions are read as Bullet reads them, or repaired, each with a
// warning:
// - mass 0 is a massless link; its geometry gives it no mass either;
// - mass > 0 with every <inertia> entry 0 takes the inertia of
//   `geometry_in_link` (its collision geometry, uniform density) scaled to
//   that mass, or with no geometry a ball of water's of that mass;
// - principal moments that miss I1 + I2 >= I3 by at most
//   kMaxTriangleDeficit of I3 (rounding in CAD exports) have I1 and I2
//   scaled up until it holds;
// - with `balance`, any tensor that is not positive definite or misses
//   I1 + I2 >= I3 (PR2's, TIAGo's, ANYmal's) keeps its principal axes, its
//   smaller moments raised to 1e-3 of the largest and then until
//   I1 + I2 = I3; without, it is refused.
inline constexpr double kMaxTriangleDeficit = 0.1;
physics::Result<InertialReading> ReadInertial(const urdf::Link& link,
                                              const physics::MassProperties& geometry_in_link,
                                              bool balance);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_ELEMENTS_H_
