// Validation errors that name the offending field.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace skyfarm::api {

// One invalid field: "camera.width: must be an integer in [1, 16384], got -3".
struct FieldError {
  std::string path;   // "camera.width", "atmosphere.constituents[0].density.type"
  std::string rule;   // "must be an integer in [1, 16384]"
  std::string value;  // the offending JSON value as text ("-3"), empty if absent

  std::string message() const;
};

// Thrown by the parsers when a request has one or more invalid fields; what()
// lists them all, one per line.
class ValidationError : public std::runtime_error {
 public:
  explicit ValidationError(std::vector<FieldError> errors);
  const std::vector<FieldError>& errors() const { return errors_; }

 private:
  std::vector<FieldError> errors_;
};

}  // namespace skyfarm::api
