#include "server/timelapse/timelapse_record.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "common/image/atomic_file.h"
#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

constexpr int kVersion = 1;

template <class T>
T field(const nlohmann::json& j, const char* name) {
  if (!j.contains(name)) throw std::runtime_error(std::string("missing field ") + name);
  try {
    return j.at(name).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error(std::string("field ") + name + " has the wrong type");
  }
}

}  // namespace

nlohmann::json record_json(const TimelapseRecord& r) {
  nlohmann::json j = {{"version", kVersion},
          {"id", r.id},
          {"request", r.request},
          {"sequence", r.sequence},
          {"created_unix", r.created_unix},
          {"state", to_string(r.state)},
          {"failure", r.failure},
          {"idempotency_key", r.idempotency_key},
          {"render_ids", r.render_ids},
          {"exposure_ev100", r.exposure_ev100},
          {"contact_sheet", r.contact_sheet},
          {"video", r.video},
          {"video_reason", r.video_reason},
          {"finished_unix", r.finished_unix}};
  if (!r.name.empty()) j["name"] = r.name;
  return j;
}

TimelapseRecord record_from_json(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("not a JSON object");
  if (field<int>(j, "version") != kVersion) throw std::runtime_error("unknown version");
  TimelapseRecord r;
  r.id = field<std::string>(j, "id");
  if (!j.contains("request")) throw std::runtime_error("missing field request");
  r.request = j.at("request");
  r.sequence = field<std::int64_t>(j, "sequence");
  r.created_unix = field<double>(j, "created_unix");
  const std::string state = field<std::string>(j, "state");
  const std::optional<JobState> known = parse_job_state(state);
  if (!known) throw std::runtime_error("unknown state \"" + state + "\"");
  r.state = *known;
  r.failure = field<std::string>(j, "failure");
  r.idempotency_key = field<std::string>(j, "idempotency_key");
  r.render_ids = field<std::vector<std::string>>(j, "render_ids");
  r.exposure_ev100 = field<std::vector<double>>(j, "exposure_ev100");
  r.contact_sheet = field<bool>(j, "contact_sheet");
  r.video = field<bool>(j, "video");
  r.video_reason = field<std::string>(j, "video_reason");
  r.finished_unix = field<double>(j, "finished_unix");
  if (j.contains("name")) r.name = field<std::string>(j, "name");
  return r;
}

void save_record(const fs::path& root, const TimelapseRecord& record) {
  const fs::path dir = root / record.id;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw StorageError("cannot create " + dir.string() + ": " + ec.message());
  const std::string text = record_json(record).dump(1);
  try {
    AtomicFile::write_file(dir / "timelapse.json", text.data(), text.size());
  } catch (const FileWriteError& e) {
    throw StorageError(e.what());
  }
}

std::vector<TimelapseRecord> load_records(const fs::path& root, std::vector<std::string>* problems) {
  std::vector<TimelapseRecord> out;
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return out;
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    const fs::path file = entry.path() / "timelapse.json";
    if (!fs::is_regular_file(file, ec)) continue;
    try {
      std::ifstream in(file, std::ios::binary);
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      TimelapseRecord r = record_from_json(nlohmann::json::parse(text));
      if (r.id != entry.path().filename().string()) throw std::runtime_error("its id is not its folder's name");
      out.push_back(std::move(r));
    } catch (const std::exception& e) {
      if (problems) problems->push_back(file.string() + ": " + e.what());
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.sequence < b.sequence; });
  return out;
}

}  // namespace skyfarm::server
