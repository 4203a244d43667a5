// Instants in UTC: a strict ISO 8601 / RFC 3339 parser, the proleptic Gregorian
// calendar arithmetic behind it, and the Julian Day of an instant.
#include "common/sun/utc_time.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace skyfarm {
namespace {

constexpr std::int64_t kSecondsPerDay = 86400;
// Julian Day of the Unix epoch 1970-01-01T00:00:00Z (Meeus, "Astronomical
// Algorithms", 2nd ed., ch. 7: JD 2440587.5).
constexpr double kJulianDayOfUnixEpoch = 2440587.5;
// The largest UTC offset accepted: ±18:00, the bound of java.time.ZoneOffset and
// similar ISO 8601 libraries (civil time zones span -12:00 to +14:00).
constexpr int kMaxOffsetMinutes = 18 * 60;

// Floor division and the matching non-negative remainder, for instants before 1970.
std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// Sets *error (when given) and returns nullopt, so that every failure is one line.
std::optional<UtcInstant> fail(std::string* error, std::string reason) {
  if (error) *error = std::move(reason);
  return std::nullopt;
}

// A cursor over the text being parsed: fixed-width digit fields and literals.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[pos_]; }
  std::string_view rest() const { return text_.substr(pos_); }
  void skip() { ++pos_; }

  // Consumes `c` if it is next.
  bool accept(char c) {
    if (peek() != c) return false;
    ++pos_;
    return true;
  }

  // Consumes exactly `width` ASCII digits into *value; consumes nothing on failure.
  bool digits(int width, int* value) {
    if (text_.size() - pos_ < static_cast<std::size_t>(width)) return false;
    int v = 0;
    for (int i = 0; i < width; ++i) {
      const char c = text_[pos_ + static_cast<std::size_t>(i)];
      if (c < '0' || c > '9') return false;
      v = v * 10 + (c - '0');
    }
    pos_ += static_cast<std::size_t>(width);
    *value = v;
    return true;
  }

  // Consumes one or more digits as the decimal fraction 0.d1d2d3...; false if none.
  bool fraction(double* value) {
    std::string digits = "0.";
    while (!at_end() && peek() >= '0' && peek() <= '9') digits += text_[pos_++];
    if (digits.size() == 2) return false;
    *value = 0.0;
    std::from_chars(digits.data(), digits.data() + digits.size(), *value);  // correctly rounded
    return true;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

// The parsed fields of an instant's local wall-clock time and its offset.
struct Fields {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  double fraction = 0.0;
  int offset_minutes = 0;  // local time = UTC + offset
};

// A month or day as two digits, for error messages.
std::string two(int v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%02d", v);
  return buf;
}

// Date part "YYYY-MM-DD", range-checked against the proleptic Gregorian calendar.
bool parse_date(Cursor& in, Fields* f, std::string* error) {
  auto bad = [&](std::string reason) {
    if (error) *error = std::move(reason);
    return false;
  };
  if (!in.digits(4, &f->year)) return bad("year must be 4 digits (YYYY)");
  if (!in.accept('-')) return bad("expected '-' after the year (YYYY-MM-DD)");
  if (!in.digits(2, &f->month)) return bad("month must be 2 digits (MM)");
  if (f->month < 1 || f->month > 12) return bad("month must be in [1, 12]");
  if (!in.accept('-')) return bad("expected '-' after the month (YYYY-MM-DD)");
  if (!in.digits(2, &f->day)) return bad("day must be 2 digits (DD)");
  const unsigned last = last_day_of_month(f->year, static_cast<unsigned>(f->month));
  if (f->day < 1 || f->day > static_cast<int>(last)) {
    if (f->month == 2 && f->day == 29)
      return bad("February " + std::to_string(f->year) + " has 28 days (not a leap year)");
    return bad("day must be in [1, " + std::to_string(last) + "] for " + std::to_string(f->year) +
               "-" + two(f->month));
  }
  return true;
}

// Time part "hh:mm[:ss[.fff...]]" (a ',' decimal sign is also ISO 8601).
bool parse_time(Cursor& in, Fields* f, std::string* error) {
  auto bad = [&](std::string reason) {
    if (error) *error = std::move(reason);
    return false;
  };
  if (!in.digits(2, &f->hour)) return bad("hour must be 2 digits (hh)");
  if (f->hour > 23) return bad("hour must be in [0, 23]");
  if (!in.accept(':')) return bad("expected ':' after the hour (hh:mm)");
  if (!in.digits(2, &f->minute)) return bad("minute must be 2 digits (mm)");
  if (f->minute > 59) return bad("minute must be in [0, 59]");
  if (!in.accept(':')) return true;  // seconds are optional
  if (!in.digits(2, &f->second)) return bad("second must be 2 digits (ss)");
  if (f->second > 59) return bad("second must be in [0, 59] (leap seconds are not supported)");
  if (in.accept('.') || in.accept(',')) {
    if (!in.fraction(&f->fraction)) return bad("a decimal point must be followed by digits");
  }
  return true;
}

// UTC offset "Z" | "±hh:mm" | "±hhmm", at most ±18:00.
bool parse_offset(Cursor& in, Fields* f, std::string* error) {
  auto bad = [&](std::string reason) {
    if (error) *error = std::move(reason);
    return false;
  };
  if (in.accept('Z')) {
    f->offset_minutes = 0;
    return true;
  }
  const char sign = in.peek();
  if (sign != '+' && sign != '-') {
    if (in.at_end()) return bad("a UTC offset (Z or ±hh:mm) is required");
    return bad("expected a UTC offset (Z or ±hh:mm), got '" + std::string(in.rest()) + "'");
  }
  in.skip();
  int hours = 0;
  int minutes = 0;
  if (!in.digits(2, &hours)) return bad("UTC offset hours must be 2 digits (±hh:mm)");
  in.accept(':');  // ±hh:mm or ±hhmm
  if (!in.digits(2, &minutes)) return bad("UTC offset minutes must be 2 digits (±hh:mm)");
  if (minutes > 59) return bad("UTC offset minutes must be in [0, 59]");
  const int total = hours * 60 + minutes;
  if (total > kMaxOffsetMinutes) return bad("UTC offset must be within ±18:00");
  f->offset_minutes = sign == '-' ? -total : total;
  return true;
}

}  // namespace

// Leap years of the proleptic Gregorian calendar: every 4th year, except
// centuries not divisible by 400 (Gregory XIII, Inter gravissimas, 1582).
bool is_leap_year(std::int64_t y) { return y % 4 == 0 && (y % 100 != 0 || y % 400 == 0); }

// Month lengths 31 28|29 31 30 31 30 31 31 30 31 30 31.
unsigned last_day_of_month(std::int64_t y, unsigned m) {
  static constexpr unsigned kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (m < 1 || m > 12) return 0;
  return (m == 2 && is_leap_year(y)) ? 29 : kDays[m - 1];
}

// Days since 1970-01-01 of a proleptic Gregorian date.  Algorithm of
// H. Hinnant, "chrono-Compatible Low-Level Date Algorithms" (2013),
// http://howardhinnant.github.io/date_algorithms.html, "days_from_civil":
//  * Shift the year to start on 1 March, so that the leap day is the last day of
//    the (shifted) year: y' = y - [m <= 2], month index mp = (m + 9) mod 12 with
//    March = 0 ... February = 11.
//  * Split y' into 400-year eras (146097 days each, the calendar's exact period):
//    era = floor(y' / 400), year of era yoe = y' - 400 era in [0, 399].
//  * Day of the shifted year: the month lengths from March, 31 30 31 30 31 31 30
//    31 30 31 31 (28|29), are reproduced exactly by the linear-floor formula
//    doy = floor((153 mp + 2) / 5) + d - 1 (153 days per 5 months).
//  * Day of era: doe = 365 yoe + floor(yoe/4) - floor(yoe/100) + doy (the leap
//    days of the whole years before, the era starting right after a leap day).
//  * 0000-03-01 is day -719468 from 1970-01-01, hence the final shift.
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = floor_div(y, 400);
  const std::int64_t yoe = y - era * 400;                                        // [0, 399]
  const std::int64_t mp = (static_cast<std::int64_t>(m) + 9) % 12;                // Mar = 0
  const std::int64_t doy = (153 * mp + 2) / 5 + static_cast<std::int64_t>(d) - 1;  // [0, 365]
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;                 // [0, 146096]
  return era * 146097 + doe - 719468;
}

// Inverse of days_from_civil (Hinnant, op. cit., "civil_from_days"): split the
// day count into 400-year eras, recover the year of era from the day of era by
// removing the leap days (doe - doe/1460 + doe/36524 - doe/146096 counts a
// 365-day year for every year, exactly), then the shifted month from the day of
// the year by inverting doy = (153 mp + 2) / 5: mp = (5 doy + 2) / 153.
CivilDate civil_from_days(std::int64_t days) {
  const std::int64_t z = days + 719468;
  const std::int64_t era = floor_div(z, 146097);
  const std::int64_t doe = z - era * 146097;                                     // [0, 146096]
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;  // [0, 399]
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);              // [0, 365]
  const std::int64_t mp = (5 * doy + 2) / 153;                                   // [0, 11]
  CivilDate date;
  date.day = static_cast<unsigned>(doy - (153 * mp + 2) / 5 + 1);
  date.month = static_cast<unsigned>(mp < 10 ? mp + 3 : mp - 9);
  date.year = yoe + era * 400 + (date.month <= 2 ? 1 : 0);
  return date;
}

// JD = 2440587.5 + unix_seconds / 86400 (the Unix epoch is JD 2440587.5; UTC
// days of 86400 s, leap seconds ignored as POSIX time does).  Whole days and the
// second of the day are added separately to keep the double's precision.
double UtcInstant::julian_day() const {
  const std::int64_t days = floor_div(unix_seconds, kSecondsPerDay);
  const std::int64_t second_of_day = unix_seconds - days * kSecondsPerDay;
  return (kJulianDayOfUnixEpoch + static_cast<double>(days)) +
         (static_cast<double>(second_of_day) + fraction) / static_cast<double>(kSecondsPerDay);
}

// Calendar fields from civil_from_days, seconds of the day from the remainder;
// the expanded "+YYYYY" form of ISO 8601 outside years 0000-9999.
std::string UtcInstant::to_iso8601() const {
  // Round the fraction to milliseconds, carrying into the seconds.
  std::int64_t seconds = unix_seconds;
  std::int64_t millis = std::llround(fraction * 1000.0);
  seconds += floor_div(millis, 1000);  // also tolerates a fraction outside [0, 1)
  millis -= floor_div(millis, 1000) * 1000;
  const std::int64_t days = floor_div(seconds, kSecondsPerDay);
  const std::int64_t sod = seconds - days * kSecondsPerDay;
  const CivilDate date = civil_from_days(days);
  char year[24];
  if (date.year >= 0 && date.year <= 9999)
    std::snprintf(year, sizeof year, "%04lld", static_cast<long long>(date.year));
  else  // ISO 8601 expanded year representation
    std::snprintf(year, sizeof year, "%+05lld", static_cast<long long>(date.year));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s-%02u-%02uT%02d:%02d:%02d", year, date.month, date.day,
                static_cast<int>(sod / 3600), static_cast<int>(sod / 60 % 60), static_cast<int>(sod % 60));
  std::string out = buf;
  if (millis != 0) {
    std::snprintf(buf, sizeof buf, ".%03lld", static_cast<long long>(millis));
    out += buf;
  }
  return out + "Z";
}

// ISO 8601 extended format / RFC 3339 profile: date, 'T' or ' ', time, offset;
// nothing may follow.  The instant is the local wall-clock time minus the offset.
std::optional<UtcInstant> parse_iso8601(std::string_view text, std::string* error) {
  if (text.empty()) return fail(error, "empty time; expected YYYY-MM-DDThh:mm[:ss]±hh:mm");
  Cursor in(text);
  Fields f;
  std::string reason;
  if (!parse_date(in, &f, &reason)) return fail(error, reason);
  if (in.at_end()) return fail(error, "a time of day (Thh:mm) and a UTC offset are required");
  if (!in.accept('T') && !in.accept(' ')) return fail(error, "expected 'T' or ' ' between the date and the time");
  if (!parse_time(in, &f, &reason)) return fail(error, reason);
  if (!parse_offset(in, &f, &reason)) return fail(error, reason);
  if (!in.at_end()) return fail(error, "unexpected characters after the UTC offset: '" + std::string(in.rest()) + "'");

  // Local wall-clock time minus the offset is UTC.
  UtcInstant t;
  t.unix_seconds = days_from_civil(f.year, static_cast<unsigned>(f.month), static_cast<unsigned>(f.day)) *
                       kSecondsPerDay +
                   f.hour * 3600 + f.minute * 60 + f.second - static_cast<std::int64_t>(f.offset_minutes) * 60;
  // Very long digit strings may round the sum up to 1; keep the invariant [0, 1).
  t.fraction = f.fraction < 1.0 ? f.fraction : std::nextafter(1.0, 0.0);
  if (error) error->clear();
  return t;
}

// The year of the UTC calendar date containing the instant.
int utc_year(const UtcInstant& t) {
  return static_cast<int>(civil_from_days(floor_div(t.unix_seconds, kSecondsPerDay)).year);
}

// year + (seconds since 1 January 00:00 UTC) / (seconds in that year).
double utc_decimal_year(const UtcInstant& t) {
  const std::int64_t year = civil_from_days(floor_div(t.unix_seconds, kSecondsPerDay)).year;
  const std::int64_t start = days_from_civil(year, 1, 1) * kSecondsPerDay;
  const std::int64_t length = (is_leap_year(year) ? 366 : 365) * kSecondsPerDay;
  return static_cast<double>(year) +
         (static_cast<double>(t.unix_seconds - start) + t.fraction) / static_cast<double>(length);
}

}  // namespace skyfarm
