// What the web console needs of the job service: a render's name stored with
// its job (kept out of the canonical request, so that it shares results and
// bytes with the unnamed request), reported with the request it asked for
// and its sample target in the status and the list, kept across a restart
// and read from databases made before names existed; and workers an
// operator drains, which get no new units until resumed.
#include <gtest/gtest.h>

#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "api/render_request.h"
#include "server/jobs/job_service.h"
#include "server/jobs/job_store.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPlain = R"({
  "location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
  "time": "2013-05-27T20:25:00-04:00",
  "camera": {"projection": "equirectangular", "width": 16, "height": 8},
  "quality": {"samples_per_pixel": 8}})";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_console_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

// kPlain with a name.
api::RenderRequest named(const std::string& name) {
  api::RenderRequest r = api::parse_render_request(kPlain);
  r.name = name;
  return r;
}

TEST(JobConsole, TheNameIsReportedWithTheRequestAndSurvivesARestart) {
  const fs::path dir = fresh_dir("name");
  std::string id;
  {
    JobService service(dir);
    id = service.submit(named("Ithaca dusk"), std::nullopt).id;
    const nlohmann::json status = *service.status(id);
    EXPECT_EQ(status["name"], "Ithaca dusk");
    // What it asked for: the canonical request, without the name.
    EXPECT_EQ(status["request"], api::to_canonical_json(api::parse_render_request(kPlain)));
    EXPECT_FALSE(status["request"].contains("name"));
    EXPECT_EQ(status["request"]["location"]["latitude_deg"], 42.44);
    EXPECT_EQ(status["request"]["time"], "2013-05-28T00:25:00Z");  // canonical: in UTC
    EXPECT_EQ(status["progress"]["samples_per_pixel_target"], 8);
    EXPECT_EQ(status["progress"]["samples_per_pixel"], 0);
    const nlohmann::json list = service.list(0, 10);
    ASSERT_EQ(list.size(), 1u);
    EXPECT_EQ(list[0]["name"], "Ithaca dusk");
    EXPECT_EQ(list[0]["request"]["camera"]["projection"], "equirectangular");
    EXPECT_EQ(list[0]["method"], "path");

    // The same request by another name is the same render (the result
    // cache's key has no name); the render keeps the name it was given.
    const SubmitResult again = service.submit(named("another name"), std::nullopt);
    EXPECT_EQ(again.id, id);
    EXPECT_FALSE(again.created);
    EXPECT_EQ((*service.status(id))["name"], "Ithaca dusk");
    // Unnamed: null.
    api::RenderRequest other = api::parse_render_request(kPlain);
    other.seed = 2;
    EXPECT_TRUE((*service.status(service.submit(other, std::nullopt).id))["name"].is_null());
  }
  JobService restarted(dir);
  EXPECT_EQ((*restarted.status(id))["name"], "Ithaca dusk");
}

// A database of before names (the jobs table without its column) opens, its
// jobs without a name, and takes named jobs from then on.
TEST(JobConsole, ADatabaseFromBeforeNamesGainsTheColumn) {
  const fs::path dir = fresh_dir("migration");
  fs::create_directories(dir);
  const fs::path db_path = dir / "skyfarm.db";
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(db_path.c_str(), &db), SQLITE_OK);
    const char* sql =
        "CREATE TABLE jobs (id TEXT PRIMARY KEY, request TEXT NOT NULL, request_hash TEXT NOT NULL,"
        " priority INTEGER NOT NULL, state TEXT NOT NULL, created REAL NOT NULL, failure TEXT NOT NULL DEFAULT '',"
        " idempotency_key TEXT NOT NULL DEFAULT '', sequence INTEGER NOT NULL);"
        "INSERT INTO jobs VALUES ('00000000000000aa', '{}', 'h', 50, 'done', 1.5, '', '', 1);";
    ASSERT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
  }
  {
    JobStore store(db_path);
    const std::vector<JobRecord> old = store.load_all();
    ASSERT_EQ(old.size(), 1u);
    EXPECT_EQ(old[0].id, "00000000000000aa");
    EXPECT_EQ(old[0].name, "");
    EXPECT_EQ(old[0].state, JobState::kDone);
    JobRecord r;
    r.id = "00000000000000bb";
    r.request = "{}";
    r.request_hash = "g";
    r.sequence = 2;
    r.name = "second";
    store.insert(r);
  }
  JobStore reopened(db_path);  // the column is there now: not added twice
  const std::vector<JobRecord> all = reopened.load_all();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].name, "");
  EXPECT_EQ(all[1].name, "second");
}

TEST(JobConsole, ADrainedWorkerGetsNoUnitsUntilResumed) {
  JobService service(fresh_dir("drain"));
  service.worker_joined("w1", {{"cores", 1}});
  service.worker_joined("w2", {{"cores", 1}});
  // Many units (tiles x passes), so that there are some left for every ask below.
  service.submit(api::parse_render_request(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 90},
    "camera": {"projection": "equirectangular", "width": 128, "height": 64},
    "quality": {"samples_per_pixel": 256}})"),
                 std::nullopt);
  EXPECT_FALSE(service.set_worker_draining("nobody", true)) << "an unknown worker is not drained";
  ASSERT_TRUE(service.set_worker_draining("w1", true));
  for (const nlohmann::json& w : service.workers()) EXPECT_EQ(w["draining"], w["id"] == "w1") << w.dump();
  // w1 gets nothing, however often it asks; w2 gets the units.
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(service.next_unit("w1").has_value());
  const std::optional<UnitAssignment> unit = service.next_unit("w2");
  ASSERT_TRUE(unit.has_value());
  ASSERT_TRUE(service.set_worker_draining("w2", true));
  EXPECT_FALSE(service.next_unit("w2").has_value());
  // Drained workers stay drained when they reconnect; resume undoes it.
  service.worker_left("w1");
  service.worker_joined("w1", {{"cores", 1}});
  EXPECT_FALSE(service.next_unit("w1").has_value());
  ASSERT_TRUE(service.set_worker_draining("w1", false));
  EXPECT_TRUE(service.next_unit("w1").has_value());
  for (const nlohmann::json& w : service.workers()) EXPECT_EQ(w["draining"], w["id"] == "w2") << w.dump();
}

}  // namespace
}  // namespace skyfarm::server
