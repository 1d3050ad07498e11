// Results for operations that take external input: either a value or a
// message saying what was wrong with the input. Bad input never aborts.
#ifndef RIGID_BODY_SIM_PHYSICS_RESULT_H_
#define RIGID_BODY_SIM_PHYSICS_RESULT_H_

#include <cassert>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

namespace rigid_body_sim::physics {

// A number as error messages show it: the shortest of fixed or scientific
// notation at 6 significant digits, as std::ostream prints it.
inline std::string FormatNumber(double value) {
  std::ostringstream stream;
  stream << value;
  return stream.str();
}

class Status {
 public:
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  const std::string& message() const {
    static const std::string kEmpty;
    return message_ ? *message_ : kEmpty;
  }

 private:
  Status() = default;
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

template <typename T>
class Result {
 public:
  Result(T value) : value_(std::move(value)) {}         // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    assert(!status_.ok() && "a Result built from a Status must carry an error");
  }
  static Result Error(std::string message) { return Result(Status::Error(std::move(message))); }

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  const std::string& message() const { return status_.message(); }
  const T& value() const& {
    assert(ok());
    return *value_;
  }
  T& value() & {
    assert(ok());
    return *value_;
  }
  T&& value() && {
    assert(ok());
    return std::move(*value_);
  }
  const T& operator*() const& { return value(); }
  const T* operator->() const { return &value(); }

 private:
  std::optional<T> value_;
  Status status_ = Status::Ok();
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_RESULT_H_
