#include "io/gazebo_sdf.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <tuple>
#include <vector>

#include <Eigen/Geometry>

#include "io/urdf_elements.h"
#include "rigid_body_sim/io/urdf_loader.h"

namespace rigid_body_sim::io {
namespace {

using physics::FormatNumber;
using physics::Pose;
using physics::Quat;
using physics::Result;
using physics::Status;
using physics::Vec3;

std::string Trimmed(const char* text) {
  std::string value = text == nullptr ? "" : text;
  const auto blank = [](unsigned char c) { return std::isspace(c) != 0; };
  value.erase(value.begin(), std::find_if_not(value.begin(), value.end(), blank));
  value.erase(std::find_if_not(value.rbegin(), value.rend(), blank).base(), value.end());
  return value;
}

// FormatNumber without the exponent's sign and padding: "1e6", as
// descriptions write it, rather than "1e+06".
std::string ShortNumber(double value) {
  std::string text = FormatNumber(value);
  const std::size_t e = text.find('e');
  if (e == std::string::npos) return text;
  std::size_t digits = e + 1;
  if (text[digits] == '+') text.erase(digits, 1);
  if (text[digits] == '-') ++digits;
  while (digits + 1 < text.size() && text[digits] == '0') text.erase(digits, 1);
  return text;
}

std::string ShowBounds(const Bounds& bounds) {
  const std::string low = bounds.low_name.empty() ? ShortNumber(bounds.low) : bounds.low_name;
  return std::string(bounds.open_low ? "(" : "[") + low + ", " + ShortNumber(bounds.high) + "]" +
         (bounds.unit.empty() ? "" : " " + bounds.unit);
}

bool Within(double value, const Bounds& bounds) {
  const bool above_low = bounds.open_low ? value > bounds.low : value >= bounds.low;
  return above_low && value <= bounds.high;
}

// One number of `text` from `*cursor`, which it advances; `field` names it.
Result<double> NextNumber(const std::string& text, const char** cursor, const std::string& field) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(*cursor, &end);
  const bool out_of_range = errno == ERANGE;
  if (end == *cursor) return Result<double>::Error(field + " " + Quoted(text) + " is not a number");
  // strtod reads "nan" and "inf" as numbers, and flags both overflow and a
  // result below the smallest normal double (not the number written).
  if (!std::isfinite(value) || (out_of_range && std::abs(value) > DBL_MIN)) {
    return Result<double>::Error(field + " " + Quoted(text) + " is not a finite number");
  }
  if (out_of_range) {
    return Result<double>::Error(field + " " + Quoted(text) +
                                 " underflows (its magnitude is below " + FormatNumber(DBL_MIN) +
                                 ", the smallest normal double)");
  }
  *cursor = end;
  return value;
}

// Every number of `text`.
Result<std::vector<double>> AllNumbers(const std::string& text, const std::string& field) {
  std::vector<double> numbers;
  const char* cursor = text.c_str();
  while (true) {
    while (std::isspace(static_cast<unsigned char>(*cursor)) != 0) ++cursor;
    if (*cursor == '\0') return numbers;
    Result<double> number = NextNumber(text, &cursor, field);
    if (!number.ok()) return number.status();
    numbers.push_back(*number);
  }
}

}  // namespace

std::string PluginBaseName(const std::string& filename) {
  std::string name = Trimmed(filename.c_str());
  const std::size_t slash = name.rfind('/');
  if (slash != std::string::npos) name = name.substr(slash + 1);
  if (name.rfind("lib", 0) == 0) name = name.substr(3);
  const std::string suffix = ".so";
  if (name.size() >= suffix.size() &&
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
    name.resize(name.size() - suffix.size());
  }
  return name;
}

std::string AttributeOf(const TiXmlElement& element, const char* name) {
  const char* value = element.Attribute(name);
  return value == nullptr ? "" : value;
}

const TiXmlElement* SdfScope::Find(const std::string& path) const {
  const TiXmlElement* element = element_;
  std::istringstream parts(path);
  std::string part;
  while (element != nullptr && std::getline(parts, part, '/')) {
    element = element->FirstChildElement(part.c_str());
  }
  return element;
}

std::string SdfScope::Field(const std::string& path) const {
  std::string tags;
  std::istringstream parts(path);
  std::string part;
  while (std::getline(parts, part, '/')) tags += "<" + part + ">";
  return where_ + " " + tags;
}

std::string SdfScope::String(const std::string& path, const std::string& fallback) const {
  const TiXmlElement* element = Find(path);
  return element == nullptr ? fallback : Trimmed(element->GetText());
}

Result<std::optional<double>> SdfScope::ParsedNumber(const std::string& path) const {
  const TiXmlElement* element = Find(path);
  if (element == nullptr) return std::optional<double>();
  const std::string text = Trimmed(element->GetText());
  Result<std::vector<double>> numbers = AllNumbers(text, Field(path));
  if (!numbers.ok()) return numbers.status();
  if (numbers->size() != 1) {
    return Result<std::optional<double>>::Error(Field(path) + " " + Quoted(text) +
                                                " must be one number");
  }
  return std::optional<double>(numbers->front());
}

Result<double> SdfScope::Number(const std::string& path, double fallback,
                                const Bounds& bounds) const {
  Result<std::optional<double>> number = ParsedNumber(path);
  if (!number.ok()) return number.status();
  const double value = number->value_or(fallback);
  if (!Within(value, bounds)) {
    return Result<double>::Error(Field(path) + " " + ShortNumber(value) +
                                 " is outside the allowed range " + ShowBounds(bounds));
  }
  return value;
}

Result<int> SdfScope::Count(const std::string& path, int fallback, int low, int high) const {
  Result<std::optional<double>> number = ParsedNumber(path);
  if (!number.ok()) return number.status();
  const double value = number->value_or(fallback);
  const Bounds bounds(low, high);
  if (!Within(value, bounds)) {
    return Result<int>::Error(Field(path) + " " + ShortNumber(value) +
                              " is outside the allowed range " + ShowBounds(bounds));
  }
  if (value != std::floor(value)) {
    return Result<int>::Error(Field(path) + " " + FormatNumber(value) + " is not a whole number");
  }
  return static_cast<int>(value);
}

Result<bool> SdfScope::Boolean(const std::string& path, bool fallback) const {
  const TiXmlElement* element = Find(path);
  if (element == nullptr) return fallback;
  std::string text = Trimmed(element->GetText());
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  return Result<bool>::Error(Field(path) + " " + Quoted(text) +
                             " is not a boolean (true, false, 1 or 0)");
}

Result<Vec3> SdfScope::Vector(const std::string& path, const Bounds& bounds) const {
  const TiXmlElement* element = Find(path);
  if (element == nullptr) return Vec3(Vec3::Zero());
  const std::string text = Trimmed(element->GetText());
  Result<std::vector<double>> numbers = AllNumbers(text, Field(path));
  if (!numbers.ok()) return numbers.status();
  if (numbers->size() != 3) {
    return Result<Vec3>::Error(Field(path) + " " + Quoted(text) + " must be 3 numbers, has " +
                               std::to_string(numbers->size()));
  }
  for (const double value : *numbers) {
    if (!Within(value, bounds)) {
      return Result<Vec3>::Error(Field(path) + " " + ShortNumber(value) +
                                 " is outside the allowed range " + ShowBounds(bounds));
    }
  }
  return Vec3((*numbers)[0], (*numbers)[1], (*numbers)[2]);
}

Result<Pose> SdfScope::PoseAt(const std::string& path) const {
  const TiXmlElement* element = Find(path);
  if (element == nullptr) return Pose::Identity();
  const std::string text = Trimmed(element->GetText());
  Result<std::vector<double>> numbers = AllNumbers(text, Field(path));
  if (!numbers.ok()) return numbers.status();
  if (numbers->size() != 6) {
    return Result<Pose>::Error(Field(path) + " " + Quoted(text) +
                               " must be 6 numbers (x y z roll pitch yaw), has " +
                               std::to_string(numbers->size()));
  }
  const Bounds position{-kMaxShapeSize, kMaxShapeSize, "m"};
  const Bounds angle{-kMaxSdfMagnitude, kMaxSdfMagnitude, "rad"};
  for (std::size_t i = 0; i < 6; ++i) {
    const Bounds& bounds = i < 3 ? position : angle;
    if (!Within((*numbers)[i], bounds)) {
      return Result<Pose>::Error(Field(path) + " " + ShortNumber((*numbers)[i]) +
                                 " is outside the allowed range " + ShowBounds(bounds));
    }
  }
  const std::vector<double>& n = *numbers;
  // SDF's roll, pitch and yaw are about the fixed x, y and z axes in turn.
  const Quat rotation = Eigen::AngleAxisd(n[5], Vec3::UnitZ()) *
                        Eigen::AngleAxisd(n[4], Vec3::UnitY()) *
                        Eigen::AngleAxisd(n[3], Vec3::UnitX());
  return Pose{Vec3(n[0], n[1], n[2]), rotation.normalized()};
}

Result<Quat> SdfScope::Rotation(const std::string& path) const {
  Result<Vec3> rpy = Vector(path, Bounds(-kMaxSdfMagnitude, kMaxSdfMagnitude, "rad"));
  if (!rpy.ok()) return rpy.status();
  const Quat rotation = Eigen::AngleAxisd(rpy->z(), Vec3::UnitZ()) *
                        Eigen::AngleAxisd(rpy->y(), Vec3::UnitY()) *
                        Eigen::AngleAxisd(rpy->x(), Vec3::UnitX());
  return Quat(rotation.normalized());
}

Result<bool> SdfScope::NoiseOn(const std::string& path) const {
  const TiXmlElement* noise = Find(path);
  if (noise == nullptr) return false;
  // SDF 1.5 and later write the type as an attribute, 1.4 as an element.
  std::string type = AttributeOf(*noise, "type");
  if (type.empty()) type = String(path + "/type", "");
  if (type == "none" || type.empty()) return false;
  if (type != "gaussian" && type != "gaussian_quantized") {
    return Result<bool>::Error(Field(path) + " type " + Quoted(type) +
                               " is not one of gaussian, gaussian_quantized or none");
  }
  return true;
}

Result<GaussianNoise> SdfScope::Noise(const std::string& path) const {
  Result<bool> on = NoiseOn(path);
  if (!on.ok()) return on.status();
  if (!*on) return GaussianNoise{};
  return NoiseValues(path);
}

Result<GaussianNoise> SdfScope::NoiseValues(const std::string& path) const {
  const Bounds any(-kMaxSdfMagnitude, kMaxSdfMagnitude);
  GaussianNoise read;
  for (const auto& [name, value, bounds] :
       {std::tuple<const char*, double*, Bounds>{"mean", &read.mean, any},
        {"stddev", &read.stddev, Bounds(0.0, kMaxSdfMagnitude)},
        {"bias_mean", &read.bias_mean, any},
        {"bias_stddev", &read.bias_stddev, Bounds(0.0, kMaxSdfMagnitude)}}) {
    Result<double> number = Number(path + "/" + name, 0.0, bounds);
    if (!number.ok()) return number.status();
    *value = *number;
  }
  return read;
}

Result<double> SdfScope::Rate(const std::string& path, double fallback) const {
  return Number(path, fallback, Bounds(0.0, kMaxUpdateRate, "Hz"));
}

Result<double> SdfScope::Deviation(const std::string& path) const {
  return Number(path, 0.0, Bounds(0.0, kMaxSdfMagnitude));
}

GaussianNoise WithExtraDeviation(GaussianNoise noise, double stddev) {
  noise.stddev = std::hypot(noise.stddev, stddev);
  return noise;
}

}  // namespace rigid_body_sim::io
