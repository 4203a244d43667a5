// What the server keeps of a timelapse across restarts: one JSON file per
// timelapse, <data-dir>/timelapses/<id>/timelapse.json, rewritten atomically
// (AtomicFile, fsynced) whenever it changes.  The frames themselves are
// render jobs, which persist and resume on their own (job_service.h); the
// record maps each frame to its render id.
//
// File fields: {"id", "request" (the canonical timelapse request, as JSON),
// "sequence", "created_unix", "state", "failure", "idempotency_key",
// "render_ids" (per frame; "" while not submitted), "exposure_ev100" (per
// frame, once the outputs are built), "contact_sheet" (bool), "video" (bool),
// "video_reason", "finished_unix", "version" (1)}, and "name" when the
// request gave one (records written before names were kept have none).
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "server/jobs/job_state.h"

#include <nlohmann/json.hpp>

namespace skyfarm::server {

struct TimelapseRecord {
  std::string id;
  nlohmann::json request;  // api::to_canonical_json of the timelapse request
  std::int64_t sequence = 0;  // creation order (GET /v1/timelapses lists newest first)
  double created_unix = 0.0;
  JobState state = JobState::kQueued;  // a timelapse goes through the states of a render job
  std::string failure;           // when failed: which frame and why
  std::string idempotency_key;
  std::vector<std::string> render_ids;
  std::vector<double> exposure_ev100;
  bool contact_sheet = false;
  bool video = false;
  std::string video_reason;  // when done without a video
  double finished_unix = 0.0;
  std::string name;  // the request's "name" (api/job_name.h; not in `request`); "" when none
};

nlohmann::json record_json(const TimelapseRecord& record);
// Throws std::runtime_error (naming the field) for a document that is not a record.
TimelapseRecord record_from_json(const nlohmann::json& j);

// <root>/<id>/timelapse.json, atomically; throws StorageError on failure.
void save_record(const std::filesystem::path& root, const TimelapseRecord& record);
// Every readable record under `root`, in creation order; each unreadable one
// adds a line to `problems` (the server logs them and goes on).
std::vector<TimelapseRecord> load_records(const std::filesystem::path& root, std::vector<std::string>* problems);

}  // namespace skyfarm::server
