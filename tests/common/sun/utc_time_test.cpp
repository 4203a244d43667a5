// ISO 8601 instants: offsets, calendar arithmetic, Julian Days against published
// values, and a reason for every malformed text.
#include "common/sun/utc_time.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace skyfarm {
namespace {

UtcInstant parse_ok(std::string_view text) {
  std::string error;
  const auto t = parse_iso8601(text, &error);
  EXPECT_TRUE(t.has_value()) << text << ": " << error;
  EXPECT_TRUE(error.empty()) << error;
  return t.value_or(UtcInstant{});
}

TEST(UtcTime, UnixEpochIsZero) {
  EXPECT_EQ(parse_ok("1970-01-01T00:00:00Z").unix_seconds, 0);
  EXPECT_EQ(parse_ok("1970-01-01T00:00Z").unix_seconds, 0);
  EXPECT_EQ(parse_ok("1969-12-31T23:59:59Z").unix_seconds, -1);
}

TEST(UtcTime, OffsetsConvertToTheSameInstant) {
  // 09:30 at UTC-4 is 13:30 UTC.
  const auto utc = parse_ok("2013-05-27T13:30:00Z");
  EXPECT_EQ(parse_ok("2013-05-27T09:30:00-04:00").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2013-05-27T09:30:00-0400").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2013-05-27 09:30-04:00").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2013-05-27T19:00:00+05:30").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2013-05-27T13:30:00+00:00").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2013-05-27T13:30:00-00:00").unix_seconds, utc.unix_seconds);
  // Offsets that move the date: across midnight, a month end and a year end.
  EXPECT_EQ(parse_ok("2013-05-28T03:30:00+14:00").unix_seconds, utc.unix_seconds);
  EXPECT_EQ(parse_ok("2012-12-31T20:00:00-04:00").to_iso8601(), "2013-01-01T00:00:00Z");
  EXPECT_EQ(parse_ok("2000-03-01T05:00:00+18:00").to_iso8601(), "2000-02-29T11:00:00Z");
}

TEST(UtcTime, KnownUnixTimes) {
  // POSIX time of well-known instants (date -u -d ... +%s).
  EXPECT_EQ(parse_ok("2000-01-01T00:00:00Z").unix_seconds, 946684800);
  EXPECT_EQ(parse_ok("2001-09-09T01:46:40Z").unix_seconds, 1000000000);
  EXPECT_EQ(parse_ok("2038-01-19T03:14:07Z").unix_seconds, 2147483647);
  EXPECT_EQ(parse_ok("1901-12-13T20:45:52Z").unix_seconds, -2147483648LL);
}

TEST(UtcTime, FractionalSeconds) {
  const auto t = parse_ok("2013-05-27T13:30:00.25Z");
  EXPECT_DOUBLE_EQ(t.fraction, 0.25);
  EXPECT_DOUBLE_EQ(parse_ok("2013-05-27T13:30:00,5Z").fraction, 0.5);
  EXPECT_DOUBLE_EQ(parse_ok("2013-05-27T13:30:00.123456789+01:00").fraction, 0.123456789);
  const auto many = parse_ok("2013-05-27T13:30:59.99999999999999999999Z");
  EXPECT_GE(many.fraction, 0.0);
  EXPECT_LT(many.fraction, 1.0);
}

TEST(UtcTime, JulianDayOfPublishedInstants) {
  // J2000.0 = 2000-01-01T12:00:00 (TT; here as UTC) = JD 2451545.0 (IAU definition).
  EXPECT_DOUBLE_EQ(parse_ok("2000-01-01T12:00:00Z").julian_day(), 2451545.0);
  // Meeus, Astronomical Algorithms (2nd ed. 1998), ch. 7, table of Gregorian examples.
  EXPECT_DOUBLE_EQ(parse_ok("1999-01-01T00:00:00Z").julian_day(), 2451179.5);
  EXPECT_DOUBLE_EQ(parse_ok("1987-01-27T00:00:00Z").julian_day(), 2446822.5);
  EXPECT_DOUBLE_EQ(parse_ok("1987-06-19T12:00:00Z").julian_day(), 2446966.0);
  EXPECT_DOUBLE_EQ(parse_ok("1988-01-27T00:00:00Z").julian_day(), 2447187.5);
  EXPECT_DOUBLE_EQ(parse_ok("1988-06-19T12:00:00Z").julian_day(), 2447332.0);
  EXPECT_DOUBLE_EQ(parse_ok("1900-01-01T00:00:00Z").julian_day(), 2415020.5);
  EXPECT_DOUBLE_EQ(parse_ok("1600-01-01T00:00:00Z").julian_day(), 2305447.5);
  EXPECT_DOUBLE_EQ(parse_ok("1600-12-31T00:00:00Z").julian_day(), 2305812.5);
  // Meeus example 7.a: launch of Sputnik 1, 1957 October 4.81 UT -> JD 2436116.31.
  // (0.81 d = 19:26:24.)
  EXPECT_NEAR(parse_ok("1957-10-04T19:26:24Z").julian_day(), 2436116.31, 1e-9);
  // Reda & Andreas (2004/2008), NREL/TP-560-34302, Table A5.1 worked example:
  // 2003-10-17 12:30:30 local time at UTC-7 -> JD 2452930.312847 (printed to 6 decimals).
  EXPECT_NEAR(parse_ok("2003-10-17T12:30:30-07:00").julian_day(), 2452930.312847, 5e-7);
}

TEST(UtcTime, RoundTripsThroughIso8601) {
  for (const char* s : {"2013-05-27T13:30:00Z", "2000-02-29T23:59:59Z", "1969-12-31T23:59:59Z",
                        "1600-03-01T00:00:00Z", "2400-12-31T12:34:56.789Z", "0000-01-01T00:00:00Z",
                        "9999-12-31T23:59:59.001Z"}) {
    const auto t = parse_ok(s);
    EXPECT_EQ(t.to_iso8601(), s);
    const auto again = parse_ok(t.to_iso8601());
    EXPECT_EQ(again.unix_seconds, t.unix_seconds);
    EXPECT_NEAR(again.fraction, t.fraction, 5e-4);
  }
  EXPECT_EQ(parse_ok("2013-05-27T09:30:00-04:00").to_iso8601(), "2013-05-27T13:30:00Z");
  // A fraction that rounds to a whole second carries into the seconds.
  EXPECT_EQ(parse_ok("2013-12-31T23:59:59.9999Z").to_iso8601(), "2014-01-01T00:00:00Z");
}

TEST(UtcTime, CalendarArithmeticIsConsistentDayByDay) {
  // Every day from 1599-01-01 to 2401-12-31 maps back to itself, and the day
  // count advances by one each day (covers the 1600/2000 leap and 1700/1800/1900/2100 non-leap centuries).
  std::int64_t expected = days_from_civil(1599, 1, 1);
  for (std::int64_t y = 1599; y <= 2401; ++y) {
    for (unsigned m = 1; m <= 12; ++m) {
      for (unsigned d = 1; d <= last_day_of_month(y, m); ++d) {
        ASSERT_EQ(days_from_civil(y, m, d), expected) << y << "-" << m << "-" << d;
        const CivilDate back = civil_from_days(expected);
        ASSERT_EQ(back.year, y);
        ASSERT_EQ(back.month, m);
        ASSERT_EQ(back.day, d);
        ++expected;
      }
    }
  }
  EXPECT_TRUE(is_leap_year(2000));
  EXPECT_TRUE(is_leap_year(2024));
  EXPECT_FALSE(is_leap_year(1900));
  EXPECT_FALSE(is_leap_year(2100));
  EXPECT_FALSE(is_leap_year(2023));
}

TEST(UtcTime, YearAndDecimalYear) {
  EXPECT_EQ(utc_year(parse_ok("2013-01-01T02:00:00+03:00")), 2012);
  EXPECT_EQ(utc_year(parse_ok("1969-07-20T20:17:40Z")), 1969);
  EXPECT_DOUBLE_EQ(utc_decimal_year(parse_ok("2001-01-01T00:00:00Z")), 2001.0);
  EXPECT_DOUBLE_EQ(utc_decimal_year(parse_ok("2000-07-02T00:00:00Z")), 2000.5);  // 182 of 366 days
}

TEST(UtcTime, RejectsMalformedTextWithAReason) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty"},
      {"2013-05-27T09:30:00", "a UTC offset (Z or ±hh:mm) is required"},
      {"2013-05-27T09:30", "a UTC offset (Z or ±hh:mm) is required"},
      {"2013-05-27", "time of day"},
      {"13-05-27T09:30:00Z", "year must be 4 digits"},
      {"2013/05/27T09:30:00Z", "expected '-' after the year"},
      {"2013-5-27T09:30:00Z", "month must be 2 digits"},
      {"2013-00-27T09:30:00Z", "month must be in [1, 12]"},
      {"2013-13-27T09:30:00Z", "month must be in [1, 12]"},
      {"2013-05-00T09:30:00Z", "day must be in [1, 31]"},
      {"2013-04-31T09:30:00Z", "day must be in [1, 30]"},
      {"2013-02-29T09:30:00Z", "not a leap year"},
      {"1900-02-29T09:30:00Z", "not a leap year"},
      {"2013-02-30T09:30:00Z", "day must be in [1, 28]"},
      {"2012-02-30T09:30:00Z", "day must be in [1, 29]"},
      {"2013-05-27X09:30:00Z", "expected 'T' or ' '"},
      {"2013-05-27t09:30:00Z", "expected 'T' or ' '"},
      {"2013-05-27T24:00:00Z", "hour must be in [0, 23]"},
      {"2013-05-27T9:30:00Z", "hour must be 2 digits"},
      {"2013-05-27T09:60:00Z", "minute must be in [0, 59]"},
      {"2013-05-27T0930Z", "expected ':' after the hour"},
      {"2013-05-27T09:30:60Z", "second must be in [0, 59]"},
      {"2016-12-31T23:59:60Z", "leap seconds"},
      {"2013-05-27T09:30:0Z", "second must be 2 digits"},
      {"2013-05-27T09:30:00.Z", "decimal point must be followed by digits"},
      {"2013-05-27T09:30:00+18:01", "within ±18:00"},
      {"2013-05-27T09:30:00-19:00", "within ±18:00"},
      {"2013-05-27T09:30:00+05:60", "UTC offset minutes must be in [0, 59]"},
      {"2013-05-27T09:30:00+5:00", "UTC offset hours must be 2 digits"},
      {"2013-05-27T09:30:00+05", "UTC offset minutes must be 2 digits"},
      {"2013-05-27T09:30:00z", "expected a UTC offset"},
      {"2013-05-27T09:30:00 Z", "expected a UTC offset"},
      {"2013-05-27T09:30:00Zjunk", "unexpected characters after the UTC offset"},
      {"2013-05-27T09:30:00Z ", "unexpected characters after the UTC offset"},
      {"2013-05-27T09:30:00+05:00:00", "unexpected characters after the UTC offset"},
      {" 2013-05-27T09:30:00Z", "year must be 4 digits"},
      {"now", "year must be 4 digits"},
  };
  for (const auto& [text, reason] : cases) {
    std::string error;
    EXPECT_FALSE(parse_iso8601(text, &error).has_value()) << "accepted '" << text << "'";
    EXPECT_NE(error.find(reason), std::string::npos)
        << "'" << text << "' gave reason '" << error << "', expected it to mention '" << reason << "'";
  }
  EXPECT_FALSE(parse_iso8601("2013-02-29T00:00:00Z").has_value());  // no error sink is fine
}

}  // namespace
}  // namespace skyfarm
