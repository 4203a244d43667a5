// Shared JSON field readers and writers for the render request and the
// radiance probe (docs/request-schema.md): safe body parsing, error collection,
// typed field access, the fields both requests carry (location, time, sun,
// atmosphere, method, seed) and their canonical forms.  The rules are
// documented field by field in docs/request-schema.md.
#pragma once
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/field_error.h"
#include "common/atmosphere/atmosphere_spec.h"
#include "common/core/spectral_table.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm::api {

using Json = nlohmann::json;

// "method": which integrator answers the request.
enum class Method { kPath, kLut };

// --- Limits shared by the requests.
inline constexpr int kMaxJsonDepth = 32;              // nested arrays/objects
inline constexpr std::size_t kMaxTableEntries = 100000;
inline constexpr std::size_t kMaxErrors = 100;        // listed per request
inline constexpr double kMinSpectralNm = 230.0;       // allowed wavelengths
inline constexpr double kMaxSpectralNm = 2500.0;
inline constexpr int kMinYear = 1800;                 // allowed "time" years
inline constexpr int kMaxYear = 2200;

// --- Error collection: every invalid field of one request.
class Errors {
 public:
  // Records one error; past kMaxErrors a single "too many errors" entry ends the list.
  void add(std::string path, std::string rule, std::string value = {});
  bool empty() const { return list_.empty(); }
  std::size_t size() const { return list_.size(); }
  const std::vector<FieldError>& list() const { return list_; }
  // Throws ValidationError with every recorded error, if there is one.
  void throw_if_any() const;


 private:
  std::vector<FieldError> list_;
  bool full_ = false;
};

// The offending value as short text for a message ("-3", "\"north\"",
// "[1,2,...]"): bounded in length and depth, ASCII, never throws.
std::string value_text(const Json& value);

// --- Allowed intervals of numbers.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range open_closed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
  static Range any() { return {}; }

  bool contains(double x) const;
  // " in [0, 90]", " in (0, 179]", " >= 0", or "" for any finite number.
  std::string text() const;
};

// A number as the messages and the docs print it: integers without a
// fraction ("100000000"), others in the shortest form that reads back exactly.
std::string format_number(double x);

// "path.name", or "name" at the top level.
std::string child_path(const std::string& path, std::string_view name);
// "path[index]".
std::string index_path(const std::string& path, std::size_t index);

// --- Scalar readers: return the value, or record an error and return nullopt.

// A finite number in `range`; `context` is appended to the range rule
// (" for a perspective camera").
std::optional<double> read_number(const Json& v, const std::string& path, const Range& range,
                                  Errors& errors, std::string_view context = {});
// An integer in [lo, hi]; a JSON number with no fraction (3.0) counts as one.
std::optional<std::int64_t> read_integer(const Json& v, const std::string& path, std::int64_t lo,
                                         std::int64_t hi, Errors& errors);
// An integer in [0, 2^64 - 1] ("seed").
std::optional<std::uint64_t> read_uint64(const Json& v, const std::string& path, Errors& errors);
std::optional<bool> read_boolean(const Json& v, const std::string& path, Errors& errors);

// One of a fixed set of names, mapped to an enum.
template <class E>
struct Choice {
  std::string_view name;
  E value;
};
std::string one_of_rule(std::initializer_list<std::string_view> names);
std::string one_of_rule(const std::vector<std::string_view>& names);

template <class E, std::size_t N>
std::optional<E> read_choice(const Json& v, const std::string& path, const Choice<E> (&choices)[N],
                             Errors& errors) {
  if (v.is_string()) {
    const auto& s = v.get_ref<const std::string&>();
    for (const auto& c : choices)
      if (c.name == s) return c.value;
  }
  std::vector<std::string_view> names;
  for (const auto& c : choices) names.push_back(c.name);
  errors.add(path, one_of_rule(names), value_text(v));
  return std::nullopt;
}

template <class E, std::size_t N>
std::string_view name_of(const Choice<E> (&choices)[N], E value) {
  for (const auto& c : choices)
    if (c.value == value) return c.name;
  return choices[0].name;
}

// --- Arrays of numbers: count, element range, and optionally strictly increasing.
struct ArrayRule {
  std::size_t min_count = 1;
  std::size_t max_count = kMaxTableEntries;
  Range range = Range::any();
  bool increasing = false;
};
// Records "must be an array" / "must have MIN to MAX entries" and returns false
// unless `v` is an array of that many entries.
bool expect_array(const Json& v, const std::string& path, std::size_t min_count,
                  std::size_t max_count, Errors& errors);
// Reports the array's first bad entry only (one error per array).
std::optional<std::vector<double>> read_number_array(const Json& v, const std::string& path,
                                                     const ArrayRule& rule, Errors& errors);
// "N entries" / "1 entry", the value text of a count error.
std::string entries_text(std::size_t n);

// --- Objects: unknown-field check and typed access to named fields.
class Fields {
 public:
  // `object` must be a JSON object (check with expect_object first).
  Fields(const Json& object, std::string path, Errors& errors)
      : object_(&object), path_(std::move(path)), errors_(&errors) {}

  // Reports every key not in `allowed` ("unknown field (allowed: ...)").
  void allow_only(std::initializer_list<std::string_view> allowed) const;

  const Json* find(std::string_view name) const;        // nullptr when absent
  const Json* find_value(std::string_view name) const;  // nullptr when absent or null
  std::string path_of(std::string_view name) const { return child_path(path_, name); }
  const std::string& path() const { return path_; }
  Errors& errors() const { return *errors_; }

  // Each reader leaves `out` unchanged when the field is absent or invalid and
  // returns whether it stored a value.
  bool number(std::string_view name, const Range& range, double& out) const;
  // Absent or null leaves `out` (a field whose default is "none").
  bool optional_number(std::string_view name, const Range& range, std::optional<double>& out) const;
  bool integer(std::string_view name, std::int64_t lo, std::int64_t hi, int& out) const;
  bool boolean(std::string_view name, bool& out) const;
  template <class E, std::size_t N>
  bool choice(std::string_view name, const Choice<E> (&choices)[N], E& out) const {
    const Json* v = find(name);
    if (!v) return false;
    auto c = read_choice(*v, path_of(name), choices, *errors_);
    if (c) out = *c;
    return c.has_value();
  }

 private:
  const Json* object_;
  std::string path_;
  Errors* errors_;
};

// Records "must be an object" and returns false unless `v` is an object.
bool expect_object(const Json& v, const std::string& path, Errors& errors);

// --- Body parsing.

// Parses a request body.  Malformed JSON, nesting deeper than kMaxJsonDepth, a
// number that overflows a double (named by its path) and a body that is not an
// object throw a ValidationError with that single error; duplicate keys are
// recorded in `errors`.
Json parse_json_object(std::string_view text, Errors& errors);

// Runs `read` and turns any exception but ValidationError into one, so that
// nothing else escapes a request parser whatever the input.
template <class Fn>
auto guarded(Fn read) -> decltype(read()) {
  try {
    return read();
  } catch (const ValidationError&) {
    throw;
  } catch (const std::exception& ex) {
    throw ValidationError({FieldError{"", std::string("could not be read: ") + ex.what(), ""}});
  }
}

// --- Spectral tables {"wavelengths_nm": [...], "values": [...]}: values in
// [0, max_value], at least `min_count` entries (1 = a constant where the table
// is held constant outside its range).
std::optional<SpectralTable> read_spectral_table(const Json& v, const std::string& path,
                                                 double max_value, Errors& errors,
                                                 std::size_t min_count = 1);
Json spectral_table_json(const SpectralTable& table);

// --- The fields the render request and the probe share.
inline constexpr Choice<Method> kMethods[] = {{"path", Method::kPath}, {"lut", Method::kLut}};

void read_location(const Fields& top, Location& out);
void read_time(const Fields& top, std::optional<UtcInstant>& time,
               std::optional<std::string>& time_text);
// Any field holding an instant like "time" (ISO 8601 with a UTC offset, years
// kMinYear..kMaxYear): absent or null leaves both outputs unchanged.
void read_instant(const Fields& f, std::string_view name, std::optional<UtcInstant>& time,
                  std::optional<std::string>& time_text);
void read_sun(const Fields& top, SunSpec& out);
// "now" is never a default (a render must not depend on when it ran);
// without "time" both sun angles are needed.
void require_time_or_sun(const Fields& top);
void read_atmosphere(const Fields& top, AtmosphereSpec& out);
void read_method(const Fields& top, Method& out);
void read_seed(const Fields& top, std::uint64_t& out);

// Canonical forms: every field present, defaults filled in, equivalent inputs
// mapped to one spelling (see docs/request-schema.md "Canonical form").
double canonical_number(double x);         // -0 -> 0
double canonical_azimuth(double deg);      // 360 -> 0
Json location_json(const Location& location);
Json time_json(const std::optional<UtcInstant>& time);
Json sun_json(const SunSpec& sun);
Json atmosphere_json(const AtmosphereSpec& atmosphere);
Json optional_number_json(const std::optional<double>& x);

}  // namespace skyfarm::api
