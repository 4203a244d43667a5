#include "worker/bench_sky_accuracy.h"

#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "api/probe_request.h"
#include "api/probe_spec.h"
#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/lut/lut_sky.h"
#include "common/render/probe_answer.h"
#include "common/sun/solar_position.h"
#include "worker/bruneton_evaluation.h"

// Generated as embedded_evaluation.cpp from api/examples/probe_bruneton_2017.json (worker/CMakeLists.txt).
namespace skyfarm::embedded_evaluation {
struct Entry { const char* name; const char* data; std::size_t size; };
extern const Entry kEntries[];
extern const std::size_t kEntryCount;
}  // namespace skyfarm::embedded_evaluation

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

using Table = std::vector<std::vector<double>>;  // [direction][wavelength], W m^-2 sr^-1 nm^-1

constexpr std::uint64_t kReferenceSeed = 2017;
constexpr double kMilli = 1e3;  // W -> mW

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The example probe: the atmosphere, sun and place of the evaluation, with
// its 81 directions and 31 wavelengths checked against the evaluation's own
// (the file writes the directions to 6 significant digits; the probe traces
// them as written, so `skyfarm-worker probe` on the file gives case 0's
// numbers exactly).
api::ProbeRequest evaluation_request() {
  if (embedded_evaluation::kEntryCount != 1) throw std::logic_error("embedded evaluation probe missing");
  const auto& e = embedded_evaluation::kEntries[0];
  api::ProbeRequest r = api::parse_probe_request(std::string_view(e.data, e.size));
  const auto dirs = bruneton_directions();
  if (r.directions.size() != dirs.size() || r.wavelengths_nm != bruneton_wavelengths_nm())
    throw std::logic_error("probe_bruneton_2017.json: not the evaluation's directions and wavelengths");
  for (std::size_t d = 0; d < dirs.size(); ++d)
    if (std::abs(r.directions[d].zenith_deg - dirs[d].zenith_deg) > 1e-4 ||
        std::abs(r.directions[d].azimuth_deg - dirs[d].azimuth_deg) > 1e-4)
      throw std::logic_error("probe_bruneton_2017.json: direction " + std::to_string(d) + " is not the evaluation's");
  return r;
}

api::ProbeRequest case_request(api::ProbeRequest r, const BrunetonCase& c, int samples, std::uint64_t seed,
                               api::Method method) {
  r.time = c.time;
  r.time_text.reset();
  r.samples = samples;
  r.seed = seed;
  r.method = method;
  return r;
}

// --- The reference CSV ------------------------------------------------------------

struct Reference {
  int samples = 0;
  std::vector<Table> radiance;        // per case
  std::vector<std::vector<double>> noise;  // per case, per direction: RMS standard error over wavelengths
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void write_reference(const fs::path& file, const Reference& ref, const std::vector<BrunetonCase>& cases) {
  const auto dirs = bruneton_directions();
  const auto wl = bruneton_wavelengths_nm();
  std::ofstream out(file);
  out << "case,local_time_edt,utc,direction,zenith_deg,azimuth_deg,samples,seed,stderr_rms_mW";
  for (const double w : wl) out << ",L" << fmt("%g", w) << "_mW";
  out << "\n";
  for (std::size_t c = 0; c < ref.radiance.size(); ++c)
    for (std::size_t d = 0; d < dirs.size(); ++d) {
      out << c << "," << cases[c].local_time << "," << cases[c].time.to_iso8601() << "," << d << ","
          << fmt("%.6f", dirs[d].zenith_deg) << "," << fmt("%.6f", dirs[d].azimuth_deg) << "," << ref.samples << ","
          << kReferenceSeed << "," << fmt("%.3g", ref.noise[c][d] * kMilli);
      for (const double v : ref.radiance[c][d]) out << "," << fmt("%.5g", v * kMilli);
      out << "\n";
    }
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string field; std::getline(s, field, ',');) out.push_back(field);
  return out;
}

// Reads what write_reference wrote, for the first `case_count` cases.
Reference read_reference(const fs::path& file, int case_count) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  const auto dirs = bruneton_directions();
  Reference ref;
  ref.radiance.assign(static_cast<std::size_t>(case_count), Table(dirs.size()));
  ref.noise.assign(static_cast<std::size_t>(case_count), std::vector<double>(dirs.size(), -1.0));
  std::string line;
  std::getline(in, line);
  if (split(line).size() != 9 + kBrunetonWavelengthCount) throw std::runtime_error(file.string() + ": not a reference");
  while (std::getline(in, line)) {
    const auto f = split(line);
    if (f.size() != 9 + kBrunetonWavelengthCount) throw std::runtime_error(file.string() + ": bad row: " + line);
    const int c = std::stoi(f[0]), d = std::stoi(f[3]);
    if (c >= case_count) continue;
    if (c < 0 || d < 0 || d >= kBrunetonDirectionCount) throw std::runtime_error(file.string() + ": bad row: " + line);
    ref.samples = std::stoi(f[6]);
    ref.noise[c][d] = std::stod(f[8]) / kMilli;
    auto& row = ref.radiance[c][d];
    row.clear();
    for (int w = 0; w < kBrunetonWavelengthCount; ++w) row.push_back(std::stod(f[9 + w]) / kMilli);
  }
  for (const auto& per_case : ref.noise)
    for (const double n : per_case)
      if (n < 0.0) throw std::runtime_error(file.string() + ": fewer cases or directions than asked for");
  return ref;
}

// The path-traced truth of one case, with its noise per direction.
void trace_reference(const api::ProbeRequest& base, const BrunetonCase& c, int samples, int threads, Reference* ref) {
  const ProbeAnswer a =
      answer_probe(api::probe_spec(case_request(base, c, samples, kReferenceSeed, api::Method::kPath)), threads);
  std::vector<double> noise;
  for (const auto& row : *a.standard_error) {
    double s2 = 0.0;
    for (const double s : row) s2 += s * s;
    noise.push_back(std::sqrt(s2 / static_cast<double>(row.size())));
  }
  ref->radiance.push_back(a.radiance);
  ref->noise.push_back(std::move(noise));
}

// --- The scored methods -------------------------------------------------------------

struct Score {
  double rmse = 0.0, median_abs = 0.0, max_abs = 0.0;  // W m^-2 sr^-1 nm^-1
};

Score score(const Table& model, const Table& reference) {
  Score s;
  s.rmse = bruneton_case_rmse(model, reference);
  std::vector<double> abs_errors;
  for (std::size_t d = 0; d < model.size(); ++d)
    for (std::size_t w = 0; w < model[d].size(); ++w) abs_errors.push_back(std::abs(model[d][w] - reference[d][w]));
  s.median_abs = median(abs_errors);
  s.max_abs = *std::max_element(abs_errors.begin(), abs_errors.end());
  return s;
}

// GET /v1/sky's answer for the evaluation: one LutSky over 360-830 nm at the
// sky service's resolution (SkyServiceOptions::resolution is LutResolution{}:
// 32 bins over 360-830 nm, server/sky/http_sky.cpp bins_for), the disk
// included as /v1/sky does, read at each wavelength linearly between bin
// centres (clamped to the first and last centre).
Table sky_service_answer(const ProbeSpec& spec) {
  ProbeSpec whole_range = spec;
  whole_range.wavelengths_nm = {360.0, 830.0};
  const Scene scene = probe_scene(whole_range);
  const LutSky sky = LutSky::build(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(), 360.0, 830.0);
  const int bins = static_cast<int>(sky.grid().size());
  const double width = (830.0 - 360.0) / bins;
  Table out;
  std::vector<double> per_bin(static_cast<std::size_t>(bins));
  for (const auto& dir : spec.directions) {
    sky.radiance(dir, per_bin, true);
    std::vector<double> row;
    for (const double lambda : spec.wavelengths_nm) {
      const double u = std::clamp((lambda - 360.0) / width - 0.5, 0.0, bins - 1.0);
      const int i = std::min(static_cast<int>(u), bins - 2);
      const double t = u - i;
      row.push_back((1.0 - t) * per_bin[static_cast<std::size_t>(i)] + t * per_bin[static_cast<std::size_t>(i + 1)]);
    }
    out.push_back(std::move(row));
  }
  return out;
}

// The angle between the sun and the nearest of the evaluation's directions:
// a direction inside the disk would score the disk, which Bruneton's sky
// radiance leaves out.
double nearest_direction_to_sun_deg(const ProbeSpec& spec, double sun_zenith_deg, double sun_azimuth_deg) {
  const glm::dvec3 sun = direction_from_zenith_azimuth(sun_zenith_deg * kDegToRad, sun_azimuth_deg * kDegToRad);
  double best = 180.0;
  for (const auto& d : spec.directions)
    best = std::min(best, std::acos(std::clamp(glm::dot(sun, d), -1.0, 1.0)) / kDegToRad);
  return best;
}

struct CaseRow {
  BrunetonCase c;
  double sun_zenith = 0.0, sun_azimuth = 0.0, nearest_to_sun = 0.0, reference_noise = 0.0;
  Score lut, sky, path;
  double lut_cpu = 0.0, sky_cpu = 0.0, path_cpu = 0.0, path_wall = 0.0;
};

std::string mw(double w, const char* format = "%.2f") { return fmt(format, w * kMilli); }

void write_markdown(const fs::path& file, const std::vector<CaseRow>& rows, const Reference& ref, int path_samples,
                    int threads, const std::string& command) {
  std::vector<double> lut, sky, path, noise;
  double lut_cpu = 0.0, sky_cpu = 0.0, path_cpu = 0.0, path_wall = 0.0;
  for (const auto& r : rows) {
    lut.push_back(r.lut.rmse);
    sky.push_back(r.sky.rmse);
    path.push_back(r.path.rmse);
    noise.push_back(r.reference_noise);
    lut_cpu += r.lut_cpu;
    sky_cpu += r.sky_cpu;
    path_cpu += r.path_cpu;
    path_wall += r.path_wall;
  }
  std::ofstream out(file);
  out << "Bruneton's 2017 clear-sky evaluation (17 cases, 81 directions, 31 wavelengths 360-712.5 nm), "
         "Bruneton's demo atmosphere, against the path tracer at "
      << ref.samples << " samples per value (seed " << kReferenceSeed
      << "). RMSE in mW m^-2 sr^-1 nm^-1; CPU seconds per case; path tracer " << path_samples
      << " samples per value (its default), " << (threads > 0 ? std::to_string(threads) : std::string("all"))
      << " thread(s).\n\n";
  out << "| case (EDT) | sun zenith | truth noise | RMSE lut | median lut | RMSE /v1/sky | RMSE path | lut CPU s | "
         "/v1/sky CPU s | path CPU s |\n";
  out << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    out << "| " << r.c.local_time << " | " << fmt("%.2f", r.sun_zenith) << " | " << mw(r.reference_noise) << " | "
        << mw(r.lut.rmse) << " | " << mw(r.lut.median_abs) << " | " << mw(r.sky.rmse) << " | " << mw(r.path.rmse)
        << " | " << fmt("%.3f", r.lut_cpu) << " | " << fmt("%.3f", r.sky_cpu) << " | " << fmt("%.1f", r.path_cpu)
        << " |\n";
  const auto [lut_min, lut_max] = std::minmax_element(lut.begin(), lut.end());
  const auto [path_min, path_max] = std::minmax_element(path.begin(), path.end());
  out << "| **total** (RMS over cases; times summed) | | " << mw(bruneton_total_rmse(noise)) << " | **"
      << mw(bruneton_total_rmse(lut)) << "** | | " << mw(bruneton_total_rmse(sky)) << " | **"
      << mw(bruneton_total_rmse(path)) << "** | " << fmt("%.2f", lut_cpu) << " | " << fmt("%.2f", sky_cpu) << " | "
      << fmt("%.0f", path_cpu) << " |\n\n";
  out << "Per-case RMSE range: lut " << mw(*lut_min) << "-" << mw(*lut_max) << ", path " << mw(*path_min) << "-"
      << mw(*path_max) << " mW. Path tracer wall time, all cases: " << fmt("%.0f", path_wall)
      << " s. Bruneton 2008 (precomputed) against Kider's measurements: " << fmt("%.2f", kBruneton2008TotalRmse_mW)
      << " mW. Truth noise = RMS of the reference's standard errors (what a perfect model would score).\n\n";
  out << "Reproduce: `" << command << "`\n";
}

int usage() {
  std::cerr << "usage: skyfarm-worker bench sky-accuracy [--reference FILE] [--out DIR] [--cases N] [--threads N] "
               "[--repeat N] [--reference-samples N]\n";
  return 2;
}

}  // namespace

int run_bench_sky_accuracy(const std::vector<std::string>& args) {
  fs::path dir = "skyfarm-sky-accuracy";
  fs::path reference_file;
  int case_count = kBrunetonCaseCount, threads = 0, repeat = 3, reference_samples = 8192;
  std::string command = "skyfarm-worker bench sky-accuracy";
  for (std::size_t i = 1; i < args.size(); ++i) {  // args[0] is "sky-accuracy"
    const bool has_value = i + 1 < args.size();
    if (!has_value) return usage();
    const std::string& flag = args[i];
    const std::string& value = args[++i];
    if (flag == "--reference") {
      reference_file = value;
    } else if (flag == "--out") {
      dir = value;
    } else if (flag == "--cases") {
      case_count = std::clamp(std::atoi(value.c_str()), 1, kBrunetonCaseCount);
    } else if (flag == "--threads") {
      threads = std::max(0, std::atoi(value.c_str()));
    } else if (flag == "--repeat") {
      repeat = std::max(1, std::atoi(value.c_str()));
    } else if (flag == "--reference-samples") {
      reference_samples = std::max(1, std::atoi(value.c_str()));
    } else {
      return usage();
    }
    command += " " + flag + " " + value;
  }
  fs::create_directories(dir);
  const api::ProbeRequest base = evaluation_request();
  const std::vector<BrunetonCase> all_cases = bruneton_cases();
  const std::vector<BrunetonCase> cases(all_cases.begin(), all_cases.begin() + case_count);
  const fs::path reference_out = dir / "sky_accuracy_reference.csv";

  // The truth, traced or read; either way scored as the CSV holds it (5
  // significant digits), so a rerun from the file gives the same table.
  Reference ref;
  if (reference_file.empty()) {
    ref.samples = reference_samples;
    for (const auto& c : cases) {
      const auto t0 = std::chrono::steady_clock::now();
      trace_reference(base, c, reference_samples, threads, &ref);
      std::cerr << "reference " << c.local_time << " EDT: "
                << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s\n";
    }
    write_reference(reference_out, ref, cases);
    ref = read_reference(reference_out, case_count);
  } else {
    ref = read_reference(reference_file, case_count);
    if (fs::weakly_canonical(reference_file) != fs::weakly_canonical(reference_out))
      write_reference(reference_out, ref, cases);
  }

  std::vector<CaseRow> rows;
  const int path_samples = base.samples;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const BrunetonCase& c = cases[k];
    CaseRow row;
    row.c = c;
    const SolarPosition sun = solar_position(base.location, c.time);
    row.sun_zenith = sun.zenith_deg;
    row.sun_azimuth = sun.azimuth_deg;
    double n2 = 0.0;
    for (const double n : ref.noise[k]) n2 += n * n;
    row.reference_noise = std::sqrt(n2 / static_cast<double>(ref.noise[k].size()));

    const ProbeSpec lut_spec = api::probe_spec(case_request(base, c, 1, 1, api::Method::kLut));
    row.nearest_to_sun = nearest_direction_to_sun_deg(lut_spec, row.sun_zenith, row.sun_azimuth);
    std::vector<double> lut_times, sky_times;
    Table lut, sky;
    for (int r = 0; r < repeat; ++r) {
      double t0 = cpu_seconds();
      lut = answer_probe(lut_spec, 1).radiance;
      lut_times.push_back(cpu_seconds() - t0);
      t0 = cpu_seconds();
      sky = sky_service_answer(lut_spec);
      sky_times.push_back(cpu_seconds() - t0);
    }
    row.lut = score(lut, ref.radiance[k]);
    row.sky = score(sky, ref.radiance[k]);
    row.lut_cpu = median(lut_times);
    row.sky_cpu = median(sky_times);

    const ProbeSpec path_spec = api::probe_spec(case_request(base, c, path_samples, base.seed, api::Method::kPath));
    const double cpu0 = cpu_seconds();
    const auto wall0 = std::chrono::steady_clock::now();
    const ProbeAnswer path = answer_probe(path_spec, threads);
    row.path_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    row.path_cpu = cpu_seconds() - cpu0;
    row.path = score(path.radiance, ref.radiance[k]);
    rows.push_back(row);

    std::cout << nlohmann::json{{"bench", "sky_accuracy"},
                                {"case", c.local_time},
                                {"sun_zenith_deg", row.sun_zenith},
                                {"sun_azimuth_deg", row.sun_azimuth},
                                {"nearest_direction_to_sun_deg", row.nearest_to_sun},
                                {"reference_noise_mW", row.reference_noise * kMilli},
                                {"lut_rmse_mW", row.lut.rmse * kMilli},
                                {"sky_rmse_mW", row.sky.rmse * kMilli},
                                {"path_rmse_mW", row.path.rmse * kMilli},
                                {"lut_cpu_s", row.lut_cpu},
                                {"sky_cpu_s", row.sky_cpu},
                                {"path_cpu_s", row.path_cpu},
                                {"path_wall_s", row.path_wall}}
                     .dump()
              << std::endl;
  }

  std::ofstream csv(dir / "sky_accuracy.csv");
  csv << "case,local_time_edt,utc,sun_zenith_deg,sun_azimuth_deg,nearest_direction_to_sun_deg,reference_samples,"
         "reference_noise_mW,lut_rmse_mW,lut_median_abs_mW,lut_max_abs_mW,lut_cpu_s,sky_rmse_mW,sky_median_abs_mW,"
         "sky_max_abs_mW,sky_cpu_s,path_samples,path_rmse_mW,path_median_abs_mW,path_max_abs_mW,path_cpu_s,"
         "path_wall_s\n";
  for (const auto& r : rows)
    csv << r.c.index << "," << r.c.local_time << "," << r.c.time.to_iso8601() << "," << fmt("%.4f", r.sun_zenith)
        << "," << fmt("%.4f", r.sun_azimuth) << "," << fmt("%.3f", r.nearest_to_sun) << "," << ref.samples << ","
        << mw(r.reference_noise, "%.4f") << "," << mw(r.lut.rmse, "%.4f") << "," << mw(r.lut.median_abs, "%.4f")
        << "," << mw(r.lut.max_abs, "%.4f") << "," << fmt("%.4f", r.lut_cpu) << "," << mw(r.sky.rmse, "%.4f") << ","
        << mw(r.sky.median_abs, "%.4f") << "," << mw(r.sky.max_abs, "%.4f") << "," << fmt("%.4f", r.sky_cpu) << ","
        << path_samples << "," << mw(r.path.rmse, "%.4f") << "," << mw(r.path.median_abs, "%.4f") << ","
        << mw(r.path.max_abs, "%.4f") << "," << fmt("%.2f", r.path_cpu) << "," << fmt("%.2f", r.path_wall) << "\n";
  write_markdown(dir / "sky_accuracy.md", rows, ref, path_samples, threads, command);
  return 0;
}

}  // namespace skyfarm
