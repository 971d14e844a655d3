#pragma once
// Exceptions thrown by odyn. Every message names the element (by its user-given name), the
// offending value and what to do about it.

#include <sstream>
#include <stdexcept>
#include <string>

namespace odyn {

/// Base of every odyn exception.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A model description that cannot be simulated: bad parameters, unknown bodies, ...
class ModelError : public Error {
 public:
  ModelError(std::string element, const std::string& message)
      : Error(element + ": " + message), element_(std::move(element)) {}
  const std::string& element() const { return element_; }

 private:
  std::string element_;
};

/// Assembly (initial position/velocity analysis) failed.
class AssemblyError : public Error {
 public:
  AssemblyError(std::string element, const std::string& message)
      : Error("assembly failed: " + message), element_(std::move(element)) {}
  const std::string& element() const { return element_; }

 private:
  std::string element_;
};

/// A time integration or equation solve failed during a run.
class SolverError : public Error {
 public:
  SolverError(double time, const std::string& message)
      : Error(describe(time, message)), time_(time), message_(message) {}
  double time() const { return time_; }
  /// What failed, without the time.
  const std::string& message() const { return message_; }

 private:
  static std::string describe(double time, const std::string& message) {
    std::ostringstream text;
    text << "at t = " << time << " s: " << message;
    return text.str();
  }
  double time_;
  std::string message_;
};

/// Formats a value for an error message with enough digits to be useful.
template <class T>
std::string to_text(const T& value) {
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
}

}  // namespace odyn
