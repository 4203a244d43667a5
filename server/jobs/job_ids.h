// Identifiers and wall-clock stamps shared by the job and timelapse services.
#pragma once
#include <string>

namespace skyfarm::server {

// Seconds since the Unix epoch (wall clock, for the records' created/finished stamps).
double unix_now();

// A fresh random 16-hex-digit id (thread-safe; not a secret, only unique).
std::string random_id();

}  // namespace skyfarm::server
