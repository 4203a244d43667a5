#include "server/http/http_problem.h"

#include <httplib.h>

#include <iostream>
#include <mutex>

#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace {

constexpr int kRetryAfterCapacityS = 10;  // a full queue drains in seconds, not milliseconds

std::string validation_detail(const std::vector<api::FieldError>& errors) {
  if (errors.empty()) return "the request is invalid";
  if (errors.size() == 1) return errors.front().message();
  return std::to_string(errors.size()) + " invalid fields; the first: " + errors.front().message();
}

Problem validation_problem(const api::ValidationError& e) {
  Problem p;
  p.status = 400;
  p.type = std::string(kProblemValidation);
  p.title = "The request is invalid";
  p.errors = e.errors();
  p.detail = validation_detail(p.errors);
  return p;
}

Problem typed(int status, std::string_view type, std::string title, std::string detail) {
  Problem p;
  p.status = status;
  p.type = std::string(type);
  p.title = std::move(title);
  p.detail = std::move(detail);
  return p;
}


Problem problem_for_current_exception(std::string_view context) {
  try {
    throw;
  } catch (const HttpError& e) {
    return e.problem();
  } catch (const api::ValidationError& e) {
    return validation_problem(e);
  } catch (const IdempotencyConflict& e) {
    return typed(422, kProblemIdempotencyConflict, "Idempotency-Key reused with a different request",
                 e.what());
  } catch (const CapacityExceeded& e) {
    Problem p = typed(429, kProblemCapacity, "The farm is at capacity", e.what());
    p.headers.emplace_back("Retry-After", std::to_string(kRetryAfterCapacityS));
    return p;
  } catch (const InsufficientStorage& e) {
    return typed(507, kProblemInsufficientStorage, "Not enough disk for this render", e.what());
  } catch (const StorageError& e) {
    log_server_error(context, e.what());
    return typed(507, kProblemStorage, "The server cannot store data",
                 std::string("the server's data directory cannot be written (disk full or not "
                             "writable); nothing was changed: ") + e.what());
  } catch (const std::exception& e) {
    log_server_error(context, e.what());
  } catch (...) {
    log_server_error(context, "unknown exception");
  }
  return typed(500, kProblemBlank, "", "the server failed to answer this request; it has been logged");
}

}  // namespace

void log_server_error(std::string_view context, std::string_view what) noexcept {
  try {
    static std::mutex log_mutex;
    std::lock_guard lock(log_mutex);
    std::cerr << "skyfarm-server: error in " << context << ": " << what << std::endl;
  } catch (...) {  // logging must not fail a response
  }
}

HttpError::HttpError(Problem problem)
    : std::runtime_error(problem.detail), problem_(std::move(problem)) {}

HttpError http_error(int status, std::string detail) {
  Problem p;
  p.status = status;
  p.detail = std::move(detail);
  return HttpError(std::move(p));
}

api::ValidationError invalid_parameter(std::string name, std::string rule, std::string value) {
  if (value.size() > 80) value = value.substr(0, 80) + "...";
  return api::ValidationError({api::FieldError{std::move(name), std::move(rule), std::move(value)}});
}

std::string_view status_phrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 202: return "Accepted";
    case 204: return "No Content";
    case 304: return "Not Modified";
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 406: return "Not Acceptable";
    case 408: return "Request Timeout";
    case 409: return "Conflict";
    case 410: return "Gone";
    case 411: return "Length Required";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 416: return "Range Not Satisfiable";
    case 417: return "Expectation Failed";
    case 422: return "Unprocessable Content";
    case 429: return "Too Many Requests";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 501: return "Not Implemented";
    case 502: return "Bad Gateway";
    case 503: return "Service Unavailable";
    case 504: return "Gateway Timeout";
    case 507: return "Insufficient Storage";
    default: return "Unknown";
  }
}

nlohmann::json problem_json(const Problem& problem, std::string_view instance) {
  nlohmann::json doc = {
      {"type", problem.type},
      {"title", problem.title.empty() ? std::string(status_phrase(problem.status)) : problem.title},
      {"status", problem.status},
      {"detail", problem.detail.empty() ? std::string(status_phrase(problem.status)) : problem.detail},
  };
  if (!instance.empty()) doc["instance"] = std::string(instance);
  if (!problem.errors.empty()) {
    nlohmann::json errors = nlohmann::json::array();
    for (const auto& e : problem.errors)
      errors.push_back({{"field", e.path}, {"rule", e.rule}, {"value", e.value}, {"message", e.message()}});
    doc["errors"] = std::move(errors);
  }
  return doc;
}

void send_problem(httplib::Response& res, const Problem& problem, std::string_view instance) {
  res.status = problem.status;
  for (const auto& [name, value] : problem.headers) res.set_header(name, value);
  res.set_content(dump_json(problem_json(problem, instance)), "application/problem+json");
}

Problem problem_from_exception(std::exception_ptr error, std::string_view context) noexcept {
  try {
    if (!error) return typed(500, kProblemBlank, "", "the server failed to answer this request");
    std::rethrow_exception(error);
  } catch (...) {
    try {
      return problem_for_current_exception(context);
    } catch (...) {
      return Problem{};  // out of memory while building the answer
    }
  }
}

std::string dump_json(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void send_json(httplib::Response& res, int status, const nlohmann::json& body, const char* content_type) {
  res.status = status;
  res.set_content(dump_json(body), content_type);
}

void send_json_or_throw(httplib::Response& res, int status, const std::optional<nlohmann::json>& doc,
                        const HttpError& missing) {
  if (!doc) throw missing;
  send_json(res, status, *doc);
}

}  // namespace skyfarm::server
