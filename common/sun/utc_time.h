// Instants in UTC, parsed from ISO 8601 with a UTC offset.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace skyfarm {

// A point in time: seconds since 1970-01-01T00:00:00Z (UTC, no leap seconds,
// proleptic Gregorian calendar), with sub-second precision.
struct UtcInstant {
  std::int64_t unix_seconds = 0;
  double fraction = 0.0;  // [0, 1)

  // Julian Day (UT) of this instant: JD = unix/86400 + 2440587.5.
  double julian_day() const;
  // ISO 8601 in UTC, e.g. "2013-05-27T13:30:00Z" (fraction kept to ms when non-zero).
  std::string to_iso8601() const;
};

// Parses "YYYY-MM-DDThh:mm[:ss[.fff]](Z|+hh:mm|-hh:mm)" (an offset is
// required; 'T' may be ' ').  Returns nullopt and fills `error` (a short
// human-readable reason, e.g. "month must be in [1, 12]") when the text is not
// such an instant or names an impossible date/time.
std::optional<UtcInstant> parse_iso8601(std::string_view text, std::string* error = nullptr);

// The calendar year (UTC) of an instant, for range checks.
int utc_year(const UtcInstant& t);

// The instant as a continuous decimal year (UTC): year + (time since 1 January
// 00:00) / (length of that year), e.g. 2000-07-02T00:00Z -> 2000.5.
double utc_decimal_year(const UtcInstant& t);

// --- Proleptic Gregorian calendar arithmetic (H. Hinnant's algorithms) -------
struct CivilDate {
  std::int64_t year = 1970;
  unsigned month = 1;  // [1, 12]
  unsigned day = 1;    // [1, 31]
};

bool is_leap_year(std::int64_t year);
// 28..31; 0 when `month` is not in [1, 12].
unsigned last_day_of_month(std::int64_t year, unsigned month);
// Days since 1970-01-01 (negative before) of a valid date, and its inverse.
std::int64_t days_from_civil(std::int64_t year, unsigned month, unsigned day);
CivilDate civil_from_days(std::int64_t days);

}  // namespace skyfarm
