#include "api/field_error.h"

namespace skyfarm::api {
namespace {
std::string join(const std::vector<FieldError>& errors) {
  std::string s;
  for (const auto& e : errors) {
    if (!s.empty()) s += '\n';
    s += e.message();
  }
  return s;
}
}  // namespace

std::string FieldError::message() const {
  std::string m;
  m.reserve(path.size() + rule.size() + value.size() + 16);
  m.append(path.empty() ? "(request)" : path).append(": ").append(rule);
  if (!value.empty()) m.append(", got ").append(value);
  return m;
}

ValidationError::ValidationError(std::vector<FieldError> errors)
    : std::runtime_error(join(errors)), errors_(std::move(errors)) {}

}  // namespace skyfarm::api
