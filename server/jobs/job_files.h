// A job's files beside its merged tiles, in data_dir/jobs/<id>/ (disk_budget.h
// lists them all): report.json (what the status shows beyond the tiles: the
// error history, what stopped the job, its run time) and allocation.json (an
// adaptive job's samples per pass after its pilot).  Both are written
// atomically (image/atomic_file.h), so a reader or a restart sees the old or
// the new file, never half of one.
#pragma once
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "common/image/atomic_file.h"
#include "common/render/render_plan.h"
#include "common/render/sample_allocation.h"
#include "server/jobs/job.h"

namespace skyfarm::server {

inline constexpr const char* kAllocationFile = "allocation.json";
inline constexpr const char* kReportFile = "report.json";

// Writes `text` to `path` atomically; kSynced survives a power failure.
// false when it cannot be written.
bool write_atomically(const std::filesystem::path& path, const std::string& text, AtomicFile::Durability durability);

// What the status reports beyond the merged tiles, kept in the job's
// directory so that a restart does not lose it: the error history, what
// stopped the job, and its run time so far.  Written at every state change
// and every recorded pass, but beyond the first 64 passes at most once a
// second (a small frame's passes can take milliseconds).  Best effort: a job
// whose report cannot be written still renders (its tiles are the data).
void write_report(Job& job, bool state_change);
// Reads what write_report wrote; an unreadable report is ignored (the status
// starts again from the tiles).
void read_report(Job& job);

// At most kMaxHistory entries: beyond that every second entry but the last
// goes, so a long job's history keeps its whole span at a coarser step (a
// 1x1 frame to a tight target error can run a pass per millisecond).
void thin_history(nlohmann::json* history);

// The stored allocation, or nullopt when there is none or it does not fit the plan.
std::optional<SampleAllocation> read_allocation(const std::filesystem::path& path, const RenderPlan& plan);
// Synced; throws StorageError when it cannot be written.
void write_allocation(const std::filesystem::path& path, const SampleAllocation& a);

}  // namespace skyfarm::server
