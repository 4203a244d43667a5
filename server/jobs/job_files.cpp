#include "server/jobs/job_files.h"

#include <algorithm>
#include <fstream>

#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace fs = std::filesystem;

namespace {

nlohmann::json allocation_json(const SampleAllocation& a) {
  nlohmann::json tiles = nlohmann::json::array();
  for (int t = 0; t < a.tile_count(); ++t) {
    nlohmann::json blocks = nlohmann::json::array();
    for (const PassSamples& n : a.tile(t)) blocks.push_back({n.even, n.odd});
    tiles.push_back(std::move(blocks));
  }
  return {{"samples_per_pass", tiles}};
}

}  // namespace

bool write_atomically(const std::filesystem::path& path, const std::string& text, AtomicFile::Durability durability) {
  try {
    AtomicFile file(path);
    file.write(text.data(), text.size());
    file.commit(durability);
    return true;
  } catch (const FileWriteError&) {
    return false;
  }
}

void write_report(Job& job, bool state_change) {
  const Clock::time_point now = Clock::now();
  if (!state_change && job.history.size() > 64 && now - job.report_written < std::chrono::seconds(1)) return;
  job.report_written = now;
  if (!fs::exists(job.dir)) return;
  nlohmann::json report = {{"history", job.history},
                           {"stopped_by", job.stopped_by},
                           {"elapsed_s", job.elapsed_s()}};
  if (job.released) report["released"] = {{"units_done", job.released->first}, {"passes", job.released->second}};
  // Not synced: after a power failure the last second of history may be gone
  // (an unreadable report is ignored), the tiles are still the data.
  write_atomically(job.dir / kReportFile, report.dump(), AtomicFile::Durability::kRenamed);
}

constexpr std::size_t kMaxHistory = 512;
void thin_history(nlohmann::json* history) {
  if (history->size() <= kMaxHistory) return;
  nlohmann::json kept = nlohmann::json::array();
  for (std::size_t i = 0; i + 1 < history->size(); i += 2) kept.push_back(std::move((*history)[i]));
  kept.push_back(std::move(history->back()));
  *history = std::move(kept);
}

void read_report(Job& job) {
  std::ifstream in(job.dir / kReportFile);
  if (!in) return;
  try {
    const nlohmann::json r = nlohmann::json::parse(in);
    if (r.at("history").is_array()) job.history = r.at("history");
    job.stopped_by = r.at("stopped_by").get<std::string>();
    job.elapsed_before_s = std::max(0.0, r.at("elapsed_s").get<double>());
    if (r.contains("released"))
      job.released.emplace(r["released"].at("units_done").get<std::int64_t>(), r["released"].at("passes").get<int>());
  } catch (const std::exception&) {
    // An unreadable report: the status starts again from the tiles.
  }
}

std::optional<SampleAllocation> read_allocation(const std::filesystem::path& path, const RenderPlan& plan) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<std::vector<PassSamples>> tiles;
    for (const auto& blocks : j.at("samples_per_pass")) {
      tiles.emplace_back();
      for (const auto& n : blocks) tiles.back().push_back({n.at(0).get<int>(), n.at(1).get<int>()});
    }
    return SampleAllocation::from_counts(plan, std::move(tiles));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void write_allocation(const std::filesystem::path& path, const SampleAllocation& a) {
  // Synced: the passes after the pilot are rendered with these counts, so
  // losing the file would lose the job (ResultIntake::allocate).
  if (!write_atomically(path, allocation_json(a).dump(), AtomicFile::Durability::kSynced))
    throw StorageError("cannot write " + path.string());
}

}  // namespace skyfarm::server
