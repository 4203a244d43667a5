// RFC 9457 problem documents (application/problem+json) for the HTTP API:
// every error the API answers is a Problem, built here so that status codes,
// titles, types and the "errors" extension are the same on every route.
#pragma once
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/field_error.h"

namespace httplib {
struct Response;
}

namespace skyfarm::server {

// Problem types of this API (RFC 9457 §3.1.1).  Plain HTTP errors (401, 404,
// 405, 413, 415, 500) use "about:blank", whose title is the status phrase.
inline constexpr std::string_view kProblemBlank = "about:blank";
inline constexpr std::string_view kProblemValidation = "urn:skyfarm:problem:validation-error";
inline constexpr std::string_view kProblemIdempotencyConflict = "urn:skyfarm:problem:idempotency-conflict";
inline constexpr std::string_view kProblemCapacity = "urn:skyfarm:problem:capacity-exceeded";
inline constexpr std::string_view kProblemTooManyStreams = "urn:skyfarm:problem:too-many-streams";
inline constexpr std::string_view kProblemStorage = "urn:skyfarm:problem:storage-error";
inline constexpr std::string_view kProblemInsufficientStorage = "urn:skyfarm:problem:insufficient-storage";
inline constexpr std::string_view kProblemImageNotReady = "urn:skyfarm:problem:image-not-ready";
inline constexpr std::string_view kProblemNoProbeWorkers = "urn:skyfarm:problem:no-probe-workers";
inline constexpr std::string_view kProblemProbeTimeout = "urn:skyfarm:problem:probe-timeout";
inline constexpr std::string_view kProblemProbeFailed = "urn:skyfarm:problem:probe-failed";

struct Problem {
  int status = 500;
  std::string type = std::string(kProblemBlank);
  std::string title;                    // empty: the status phrase
  std::string detail;
  std::vector<api::FieldError> errors;  // the "errors" extension, when not empty
  std::vector<std::pair<std::string, std::string>> headers;  // Retry-After, Allow, WWW-Authenticate, ...
};

// A Problem thrown by a route handler; the handler's guard answers it.
class HttpError : public std::runtime_error {
 public:
  explicit HttpError(Problem problem);
  const Problem& problem() const { return problem_; }

 private:
  Problem problem_;
};

// Shorthands for the common cases.
HttpError http_error(int status, std::string detail);
// 400 naming one request part ("offset", "id", "Idempotency-Key"): a validation problem.
api::ValidationError invalid_parameter(std::string name, std::string rule, std::string value);

// "Not Found", "Unprocessable Content", ... ("Unknown" for codes not used here).
std::string_view status_phrase(int status);

// The problem document; `instance` is the request path (omitted when empty).
nlohmann::json problem_json(const Problem& problem, std::string_view instance);

// Sets status, headers and the problem+json body of `res`.
void send_problem(httplib::Response& res, const Problem& problem, std::string_view instance);

// The Problem for an exception thrown while answering a request:
// ValidationError 400, HttpError its own, IdempotencyConflict 422,
// CapacityExceeded 429, InsufficientStorage 507 (the disk budget), StorageError 507, anything else 500 with a generic
// detail (the message goes to stderr, never to the client).  Never throws.
Problem problem_from_exception(std::exception_ptr error, std::string_view context) noexcept;

// One line on stderr for the operator (serialised across threads).
void log_server_error(std::string_view context, std::string_view what) noexcept;

// Compact JSON text that never throws on invalid UTF-8 (replaced by U+FFFD).
std::string dump_json(const nlohmann::json& value);

// Sets a JSON body (application/json unless told otherwise).
void send_json(httplib::Response& res, int status, const nlohmann::json& body,
               const char* content_type = "application/json");
// Sends a resource's document (a status) with `status`, or throws `missing`
// (its 404) when the resource is unknown.
void send_json_or_throw(httplib::Response& res, int status, const std::optional<nlohmann::json>& doc,
                        const HttpError& missing);

}  // namespace skyfarm::server
