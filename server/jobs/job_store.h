// The persistent record of jobs: an SQLite database in the data directory
// (jobs and idempotency keys; when each finished job finished and whether its
// files have expired, in a table of their own so that older databases
// simply gain it).  A job's name is a column of jobs that databases written
// before it gain on opening (ALTER TABLE ... ADD COLUMN, default ''); the
// name is not in the canonical request, so it is kept here.  Merged film tiles live next to it as files
// (tile_merger.h).  Every write is a transaction; a failure to write (disk
// full, read-only directory) throws StorageError naming the database.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job_state.h"

struct sqlite3;

namespace skyfarm::server {

struct JobRecord {
  std::string id;
  std::string request;      // canonical request text
  std::string request_hash; // hex hash of `request` (result cache key)
  int priority = 50;
  JobState state = JobState::kQueued;
  double created_unix = 0.0;
  std::string failure;      // message when failed
  std::string idempotency_key;
  std::int64_t sequence = 0;  // submission order
  double finished_unix = 0.0;  // when it reached done, failed or cancelled; 0: not yet (or not known)
  bool expired = false;        // its files were removed after the retention (JobService)
  std::string name;            // the request's "name" (api/job_name.h); "" when none
};

class JobStore {
 public:
  explicit JobStore(const std::filesystem::path& database);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  void insert(const JobRecord& job);
  void set_state(const std::string& id, JobState state, const std::string& failure = "");
  void set_finished(const std::string& id, double finished_unix);
  void set_expired(const std::string& id);
  // Forgets the job (its idempotency key too).
  void remove(const std::string& id);
  // All jobs in submission order.
  std::vector<JobRecord> load_all() const;

 private:
  void exec(const std::string& sql);
  void add_name_column();
  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

}  // namespace skyfarm::server
