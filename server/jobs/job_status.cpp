// What the job service reports: a job's status document (its field names
// are a contract: docs/request-schema.md) and the farm's metrics (/metrics).
#include "server/jobs/job_book.h"

#include <cmath>

#include "common/render/render_progress.h"

namespace skyfarm::server {

nlohmann::json JobBook::status_of(const Job& job) const {
  const std::int64_t merged = job.units_done(), total = job.merger->total_units();
  const double fraction = job.progress();
  const double elapsed = job.elapsed_s();
  const int passes = job.complete_passes();
  const nlohmann::json spp = job.samples_per_pixel(passes);
  nlohmann::json plan = job.plan_json;
  if (job.allocation)
    plan["samples_per_pass_after_pilot"] = {{"min", job.allocation->min_samples_per_pass()},
                                            {"max", job.allocation->max_samples_per_pass()}};
  nlohmann::json eta = nullptr;
  if (job.active())
    if (const auto left = remaining_seconds(fraction, elapsed)) eta = *left;
  nlohmann::json workers_json = nlohmann::json::array();
  for (const auto& [id, n] : job.worker_units) workers_json.push_back({{"id", id}, {"units", n}});
  const std::string self = "/v1/renders/" + job.record.id;
  nlohmann::json estimate = nullptr, estimate_rgb = nullptr, unknown = nullptr;
  if (!job.history.empty()) {
    estimate = job.history.back()["estimated_relative_rms"];
    estimate_rgb = job.history.back().value("estimated_relative_rms_rgb", nlohmann::json(nullptr));
    unknown = job.history.back()["pixels_without_estimate"];
  }
  // What it asked for, as the console shows it (and Duplicate re-submits):
  // the canonical request; the name beside it, as the name is not part of it.
  nlohmann::json request = nlohmann::json::parse(job.record.request, nullptr, false);
  if (request.is_discarded()) request = nullptr;
  return {{"id", job.record.id},
          {"name", job.record.name.empty() ? nlohmann::json(nullptr) : nlohmann::json(job.record.name)},
          {"state", to_string(job.record.state)},
          {"method", job.plan.lut ? "lut" : "path"},
          // The LUT renderer's error is its bias against the path tracer
          // (docs/physics.md, the LUT sky); it has no Monte Carlo estimate.
          {"approximate", job.plan.lut},
          {"priority", job.record.priority},
          {"progress",
           {{"fraction", fraction},
            {"samples_per_pixel", spp},
            // The sample cap (quality.samples_per_pixel; 1048576 when only a
            // target error or a time limit stops the render).
            {"samples_per_pixel_target", job.request.quality.samples_per_pixel},
            {"units_done", merged},
            {"units_total", total}}},
          {"elapsed_s", elapsed},
          {"eta_s", eta},
          {"error",
           {{"estimated_relative_rms", estimate},
            {"estimated_relative_rms_rgb", estimate_rgb},
            {"pixels_without_estimate", unknown},
            {"sun_pixels_excluded", job.sun_pixels.size()},
            {"history", job.history}}},
          {"stopped_by", job.stopped_by.empty() ? nlohmann::json(nullptr) : nlohmann::json(job.stopped_by)},
          {"plan", plan},
          {"workers", workers_json},
          {"failure", job.record.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(job.record.failure)},
          {"created_unix", job.record.created_unix},
          {"finished_unix", is_terminal(job.record.state) ? nlohmann::json(job.record.finished_unix) : nlohmann::json()},
          // Finished longer than the retention ago: its files (images) are gone.
          {"expired", job.expired},
          {"request", request},
          {"links",
           {{"self", self}, {"exr", self + "/image.exr"}, {"png", self + "/image.png"}, {"events", self + "/events"}}}};
}

nlohmann::json JobBook::metrics() const {
  std::int64_t queue_units = 0;
  int queued = 0, running = 0, done = 0, failed = 0;
  for (const auto& [id, job] : jobs) {
    const JobState s = job->record.state;
    if (job->active()) queue_units += waiting_units(job->plan, job->merger->merged_units()) - job->in_flight;
    queued += s == JobState::kQueued;
    running += s == JobState::kRunning;
    done += s == JobState::kDone;
    failed += s == JobState::kFailed;
  }
  // Samples per second: paths merged over the last 10 s.
  const auto now = Clock::now();
  std::uint64_t paths = 0;
  for (const auto& [t, n] : recent_paths)
    if (now - t < std::chrono::seconds(10)) paths += n;
  return {{"queue_units", queue_units},
          {"units_in_flight", in_flight.size()},
          {"jobs_queued", queued},
          {"jobs_running", running},
          {"jobs_done", done},
          {"jobs_failed", failed},
          {"workers", workers.size()},
          {"samples_per_second", static_cast<double>(paths) / 10.0},
          {"unit_failures", unit_failures},
          {"requeues", requeues},
          {"results_refused", results_refused},
          {"disk_used_bytes", disk_used()},
          {"disk_budget_bytes", disk_budget},
          {"samples_total", samples_total},
          {"units_completed", units_completed}};
}

std::vector<HistogramSeries> JobBook::histograms() const {
  constexpr const char* kUnit = "skyfarm_unit_duration_seconds";
  constexpr const char* kUnitHelp = "Work units from dispatch to result merged, by render method.";
  constexpr const char* kJob = "skyfarm_job_duration_seconds";
  constexpr const char* kJobHelp = "Renders and timelapses from submission to their end, by kind and final state.";
  return {{kUnit, kUnitHelp, "method=\"path\"", unit_seconds_path.snapshot()},
          {kUnit, kUnitHelp, "method=\"lut\"", unit_seconds_lut.snapshot()},
          {kJob, kJobHelp, "kind=\"render\",state=\"done\"", job_seconds_done.snapshot()},
          {kJob, kJobHelp, "kind=\"render\",state=\"failed\"", job_seconds_failed.snapshot()},
          {kJob, kJobHelp, "kind=\"render\",state=\"cancelled\"", job_seconds_cancelled.snapshot()}};
}

}  // namespace skyfarm::server
