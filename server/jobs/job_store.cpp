#include "server/jobs/job_store.h"

#include <sqlite3.h>

#include <optional>

#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace {

// A prepared statement that finalises itself.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql, const std::filesystem::path& path) : db_(db), path_(path) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) fail("prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind(int i, const std::string& s) { sqlite3_bind_text(stmt_, i, s.c_str(), static_cast<int>(s.size()), SQLITE_TRANSIENT); }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) fail("step");
    return false;
  }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
             : std::string();
  }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw StorageError("job database " + path_.string() + ": " + what + " failed: " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::filesystem::path path_;
};

}  // namespace

JobStore::JobStore(const std::filesystem::path& database) : path_(database) {
  if (sqlite3_open(database.c_str(), &db_) != SQLITE_OK) {
    const std::string reason = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw StorageError("cannot open job database " + database.string() + ": " + reason);
  }
  sqlite3_busy_timeout(db_, 5000);
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=FULL");
  exec(
      "CREATE TABLE IF NOT EXISTS jobs ("
      " id TEXT PRIMARY KEY, request TEXT NOT NULL, request_hash TEXT NOT NULL, priority INTEGER NOT NULL,"
      " state TEXT NOT NULL, created REAL NOT NULL, failure TEXT NOT NULL DEFAULT '',"
      " idempotency_key TEXT NOT NULL DEFAULT '', sequence INTEGER NOT NULL)");
  add_name_column();
  exec(
      "CREATE TABLE IF NOT EXISTS job_ends ("
      " id TEXT PRIMARY KEY, finished REAL NOT NULL, expired INTEGER NOT NULL DEFAULT 0)");
}

JobStore::~JobStore() { sqlite3_close(db_); }

// Databases made before names were kept have no "name" column: it is added,
// every old job without a name ('').
void JobStore::add_name_column() {
  Statement columns(db_, "PRAGMA table_info(jobs)", path_);
  while (columns.step())
    if (columns.text(1) == "name") return;
  exec("ALTER TABLE jobs ADD COLUMN name TEXT NOT NULL DEFAULT ''");
}

void JobStore::exec(const std::string& sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string reason = message ? message : "unknown error";
    sqlite3_free(message);
    throw StorageError("job database " + path_.string() + ": " + reason);
  }
}

void JobStore::insert(const JobRecord& job) {
  Statement s(db_,
              "INSERT INTO jobs (id, request, request_hash, priority, state, created, failure, idempotency_key, sequence,"
              " name) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
              path_);
  s.bind(1, job.id);
  s.bind(2, job.request);
  s.bind(3, job.request_hash);
  s.bind(4, static_cast<std::int64_t>(job.priority));
  s.bind(5, to_string(job.state));
  s.bind(6, job.created_unix);
  s.bind(7, job.failure);
  s.bind(8, job.idempotency_key);
  s.bind(9, job.sequence);
  s.bind(10, job.name);
  s.step();
}

void JobStore::set_state(const std::string& id, JobState state, const std::string& failure) {
  Statement s(db_, "UPDATE jobs SET state = ?, failure = ? WHERE id = ?", path_);
  s.bind(1, to_string(state));
  s.bind(2, failure);
  s.bind(3, id);
  s.step();
}

void JobStore::set_finished(const std::string& id, double finished_unix) {
  Statement s(db_, "INSERT OR REPLACE INTO job_ends (id, finished, expired) VALUES (?, ?, 0)", path_);
  s.bind(1, id);
  s.bind(2, finished_unix);
  s.step();
}

void JobStore::set_expired(const std::string& id) {
  Statement s(db_, "UPDATE job_ends SET expired = 1 WHERE id = ?", path_);
  s.bind(1, id);
  s.step();
}

void JobStore::remove(const std::string& id) {
  exec("BEGIN");
  try {
    for (const char* sql : {"DELETE FROM jobs WHERE id = ?", "DELETE FROM job_ends WHERE id = ?"}) {
      Statement s(db_, sql, path_);
      s.bind(1, id);
      s.step();
    }
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::vector<JobRecord> JobStore::load_all() const {
  Statement s(db_,
              "SELECT jobs.id, request, request_hash, priority, state, created, failure, idempotency_key, sequence,"
              " COALESCE(job_ends.finished, 0), COALESCE(job_ends.expired, 0), name"
              " FROM jobs LEFT JOIN job_ends ON job_ends.id = jobs.id ORDER BY sequence",
              path_);
  std::vector<JobRecord> jobs;
  while (s.step()) {
    JobRecord j;
    j.id = s.text(0);
    j.request = s.text(1);
    j.request_hash = s.text(2);
    j.priority = static_cast<int>(s.integer(3));
    const std::string state = s.text(4);
    j.created_unix = s.real(5);
    j.failure = s.text(6);
    if (const std::optional<JobState> known = parse_job_state(state)) {
      j.state = *known;
    } else {  // written by a newer server, or damaged: not resumed
      j.state = JobState::kFailed;
      j.failure = "the job store holds an unknown state \"" + state + "\" for this job";
    }
    j.idempotency_key = s.text(7);
    j.sequence = s.integer(8);
    j.finished_unix = s.real(9);
    j.expired = s.integer(10) != 0;
    j.name = s.text(11);
    jobs.push_back(std::move(j));
  }
  return jobs;
}

}  // namespace skyfarm::server
