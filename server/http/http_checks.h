// Checks of the client-controlled parts of a request other than the body's
// fields: ids, query parameters, headers (Content-Type, Idempotency-Key,
// Authorization, If-None-Match, Last-Event-ID) and the body's nesting depth.
// Pure functions on text, no httplib: unit-testable and shared by the routes.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace skyfarm::server {

inline constexpr std::size_t kMaxJobIdChars = 64;
inline constexpr std::size_t kMaxIdempotencyKeyChars = 255;

// Job ids: 1 to 64 of A-Z a-z 0-9 _ - (no dots or slashes: no path traversal).
bool valid_job_id(std::string_view id);
inline constexpr std::string_view kJobIdRule = "must be 1 to 64 characters of A-Z, a-z, 0-9, _ and -";

// Idempotency-Key: 1 to 255 visible ASCII characters (0x21-0x7E).
bool valid_idempotency_key(std::string_view key);
inline constexpr std::string_view kIdempotencyKeyRule = "must be 1 to 255 visible ASCII characters";

// A request body's media type: application/json, any case, with optional
// parameters; a charset parameter must be utf-8 (or us-ascii, a subset).
enum class MediaTypeCheck { kOk, kMissing, kNotJson, kBadCharset };
MediaTypeCheck check_json_media_type(std::string_view content_type);

// A non-negative decimal integer of at most `max` (digits only: no sign,
// spaces or exponent), or nullopt.
std::optional<std::uint64_t> parse_decimal(std::string_view text, std::uint64_t max);

// True when the arrays/objects of `text` nest deeper than `max_depth` (the
// outermost value is level 1; brackets inside strings do not count).  A cheap
// scan run before the parser, which builds nothing.
bool json_deeper_than(std::string_view text, int max_depth);

// The token of an "Authorization: Bearer <token>" value (scheme in any case),
// or nullopt.
std::optional<std::string_view> bearer_token(std::string_view authorization);

// Compares in time that depends only on `expected`'s length, never on where
// the texts differ.
bool constant_time_equal(std::string_view given, std::string_view expected);

// If-None-Match against a (quoted) entity tag: "*" or any listed tag, weak
// comparison (W/ prefixes ignored), as RFC 9110 §13.1.2 asks.
bool if_none_match_matches(std::string_view if_none_match, std::string_view etag);

// Text safe to echo in a message: at most `max_chars`, control characters as '?'.
std::string printable_excerpt(std::string_view text, std::size_t max_chars = 80);
// The excerpt in double quotes: how a request part is echoed in an error.
std::string quote_text(std::string_view text);

}  // namespace skyfarm::server
