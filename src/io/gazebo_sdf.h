// Reading the SDF values of a <gazebo> <sensor> or <plugin> element, which
// Gazebo gives as element text: numbers, booleans, poses and noise blocks,
// each checked against its range. Every refusal names the element, the
// field, the value and the allowed range (gazebo_plugins.h).
#ifndef RIGID_BODY_SIM_IO_GAZEBO_SDF_H_
#define RIGID_BODY_SIM_IO_GAZEBO_SDF_H_

#include <optional>
#include <string>
#include <utility>

#include <tinyxml.h>

#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Update rates (Hz) and the bounds of most other magnitudes read here.
inline constexpr double kMaxUpdateRate = 1e4;
inline constexpr double kMaxSdfMagnitude = 1e6;

// The range a number must lie in, as messages show it: "[0, 1e4] Hz", or
// "(range_min, 1e6] m" when `low_name` names the bound.
struct Bounds {
  Bounds(double low_value, double high_value, std::string unit_name = "")
      : low(low_value), high(high_value), unit(std::move(unit_name)) {}
  // (low, high]: low itself is outside.
  Bounds OpenLow() const {
    Bounds open = *this;
    open.open_low = true;
    return open;
  }
  // Shows low as `name` in messages (a bound read from another field).
  Bounds LowNamed(std::string name) const {
    Bounds named = *this;
    named.low_name = std::move(name);
    return named;
  }

  double low;
  double high;
  std::string unit;  // e.g. "m"; empty for none
  bool open_low = false;
  std::string low_name;
};

// The file name without directories, "lib" and ".so": Gazebo finds
// "libgazebo_ros_laser.so" for "gazebo_ros_laser" too.
std::string PluginBaseName(const std::string& filename);

// An element's attribute, "" when absent.
std::string AttributeOf(const TiXmlElement& element, const char* name);

// One <sensor> or <plugin> being read; fields are named by paths below it,
// "ray/range/max" for <ray><range><max>.
class SdfScope {
 public:
  SdfScope(const TiXmlElement* element, std::string where)
      : element_(element), where_(std::move(where)) {}

  const TiXmlElement* element() const { return element_; }
  const std::string& where() const { return where_; }
  // The element at `path`, or nullptr (also when this scope has none).
  const TiXmlElement* Find(const std::string& path) const;
  bool Has(const std::string& path) const { return Find(path) != nullptr; }
  // "<ray><range><max>", prefixed with where().
  std::string Field(const std::string& path) const;

  // The text at `path`, blanks trimmed; `fallback` when absent.
  std::string String(const std::string& path, const std::string& fallback) const;
  // A finite number within `bounds`; `fallback` when absent.
  physics::Result<double> Number(const std::string& path, double fallback,
                                 const Bounds& bounds) const;
  // A whole number in [low, high]; `fallback` when absent.
  physics::Result<int> Count(const std::string& path, int fallback, int low, int high) const;
  // true, false, 1 or 0 in any case, as Gazebo's plugins read them.
  physics::Result<bool> Boolean(const std::string& path, bool fallback) const;
  // Three numbers each within `bounds`; zero when absent.
  physics::Result<physics::Vec3> Vector(const std::string& path, const Bounds& bounds) const;
  // "x y z roll pitch yaw" (SDF's <pose>); identity when absent.
  physics::Result<physics::Pose> PoseAt(const std::string& path) const;
  // A rotation from "roll pitch yaw" (an <rpyOffset>); identity when absent.
  physics::Result<physics::Quat> Rotation(const std::string& path) const;
  // The noise block at `path` (<noise type="gaussian"> or <noise><type>):
  // mean, stddev, bias_mean and bias_stddev; zero when absent or "none".
  physics::Result<GaussianNoise> Noise(const std::string& path) const;
  // Whether the noise block at `path` is present and of a Gaussian type;
  // refused for a type SDF does not have.
  physics::Result<bool> NoiseOn(const std::string& path) const;
  // The mean, stddev, bias_mean and bias_stddev below `path` (SDF 1.4's
  // <imu><noise><rate>, whose type is its parent's); zero when absent.
  physics::Result<GaussianNoise> NoiseValues(const std::string& path) const;
  // An update rate in [0, kMaxUpdateRate] Hz.
  physics::Result<double> Rate(const std::string& path, double fallback) const;
  // A standard deviation in [0, kMaxSdfMagnitude].
  physics::Result<double> Deviation(const std::string& path) const;

 private:
  physics::Result<std::optional<double>> ParsedNumber(const std::string& path) const;

  const TiXmlElement* element_;
  std::string where_;
};

// Adds the deviations of two independent Gaussian noises on the same
// reading (a sensor's and its plugin's): their variances add.
GaussianNoise WithExtraDeviation(GaussianNoise noise, double stddev);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_GAZEBO_SDF_H_
