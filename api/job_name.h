// "name": an optional label people give a render or a timelapse, shown in the
// web console and in the status documents.
//
// Parameters
//   name   string of 1 to kMaxJobNameChars characters (Unicode code points,
//          UTF-8), none of them a control character (U+0000-U+001F,
//          U+007F-U+009F); null or "" mean no name.  Anything else is a 400
//          naming "name".
//
// A name says what a render is for, not what it renders: it is never part of
// the canonical request (the text the farm hashes for the result cache and
// writes into the EXR metadata), so two requests that differ by their names
// alone share one result, and a request without a name keeps its bytes.
#pragma once
#include <cstddef>
#include <optional>
#include <string>

#include "api/json_fields.h"

namespace skyfarm::api {

inline constexpr std::size_t kMaxJobNameChars = 200;

// Reads top-level "name" into `out` (left unset when absent, null or "").
void read_job_name(const Fields& top, std::optional<std::string>& out);

// Whether `text` is a valid name: UTF-8, 1 to kMaxJobNameChars code points,
// no control characters.
bool valid_job_name(const std::string& text);

}  // namespace skyfarm::api
