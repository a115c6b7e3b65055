#include "core/run_stage.hpp"
#include "core/json_output.hpp"

#include <fcntl.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/run_record.hpp"
#include "core/sha256.hpp"

namespace imscal {

namespace fs = std::filesystem;
using nlohmann::json;

const char* to_string(StageStatus status) {
  return status == StageStatus::kOk ? "ok" : "check_failed";
}

const char* to_string(StageRun::What what) {
  switch (what) {
    case StageRun::What::kRan:
      return "ran";
    case StageRun::What::kSkipped:
      return "skipped (inputs unchanged)";
    case StageRun::What::kNotRun:
      return "not run";
  }
  return "?";
}

std::optional<std::string> RunSummary::failed_check() const {
  for (const StageRun& s : stages)
    if (s.what != StageRun::What::kNotRun && s.status == StageStatus::kCheckFailed)
      return s.name + ": " + s.message;
  return std::nullopt;
}

StageWorkspace::StageWorkspace(fs::path output_dir, fs::path run_dir,
                               std::vector<std::string> completed_upstream, std::string stage_name,
                               Progress* progress)
    : output_dir_(std::move(output_dir)),
      run_dir_(std::move(run_dir)),
      completed_upstream_(std::move(completed_upstream)),
      stage_name_(std::move(stage_name)),
      progress_(progress) {}

std::optional<fs::path> StageWorkspace::upstream_dir(const std::string& stage) const {
  if (std::find(completed_upstream_.begin(), completed_upstream_.end(), stage) ==
      completed_upstream_.end())
    return std::nullopt;
  return run_dir_ / stage;
}

void StageWorkspace::progress(double fraction) {
  if (progress_ != nullptr) progress_->update(stage_name_, fraction);
}

namespace {

constexpr const char* kRunRecordName = "run.json";
constexpr const char* kLockName = ".imscal-run.lock";
constexpr const char* kStagingPrefix = ".staging-";
constexpr const char* kOldPrefix = ".old-";

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto millis =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  ::gmtime_r(&seconds, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &utc);
  return std::string(text) + "." + (millis < 100 ? (millis < 10 ? "00" : "0") : "") +
         std::to_string(millis) + "Z";
}

bool valid_stage_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

std::optional<json> read_json_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  json value = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) return std::nullopt;
  return value;
}

// Every regular file below `folder` (relative, generic '/' form, sorted) with size and SHA-256.
json output_checksums(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(fs::relative(entry.path(), folder));
  std::sort(files.begin(), files.end());
  json outputs = json::array();
  for (const fs::path& relative : files) {
    if (relative == kStageRecordName) continue;
    outputs.push_back({{"file", relative.generic_string()},
                       {"bytes", fs::file_size(folder / relative)},
                       {"sha256", sha256_hex_of_file(folder / relative)}});
  }
  return outputs;
}

// The recorded outputs, if every one of them is still there with its recorded checksum.
bool outputs_intact(const fs::path& folder, const json& outputs) {
  if (!outputs.is_array()) return false;
  for (const json& output : outputs) {
    if (!output.contains("file") || !output.contains("sha256")) return false;
    const fs::path file = folder / output["file"].get<std::string>();
    std::error_code error;
    if (!fs::is_regular_file(file, error)) return false;
    if (output.contains("bytes") &&
        fs::file_size(file, error) != output["bytes"].get<std::uintmax_t>())
      return false;
    if (sha256_hex_of_file(file) != output["sha256"].get<std::string>()) return false;
  }
  return true;
}

// Holds an exclusive lock on the run folder for the lifetime of the object; a killed process
// releases it with its file descriptors.
class FolderLock {
 public:
  explicit FolderLock(const fs::path& folder) {
    const fs::path lock_file = folder / kLockName;
    fd_ = ::open(lock_file.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw InputError(
          (folder / kLockName).string(), 0, "",
          std::string("cannot create the run folder's lock file: ") + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw InputError(folder.string(), 0, "",
                       "another imscal run is working in this folder; wait for it to end");
    }
  }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() { ::close(fd_); }

 private:
  int fd_ = -1;
};

// Adds <run>/run.log to the default logger for the lifetime of the object.
class RunLog {
 public:
  explicit RunLog(const fs::path& file) : previous_(spdlog::default_logger()) {
    auto file_sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(file.string(), false);
    file_sink->set_pattern("%Y-%m-%dT%H:%M:%S.%e %l %v");
    file_sink->set_level(spdlog::level::debug);
    std::vector<spdlog::sink_ptr> sinks = previous_->sinks();
    // The terminal keeps the level it had; the log file gets debug messages too.
    for (auto& sink : sinks) {
      sink_levels_.push_back(sink->level());
      sink->set_level(std::max(sink->level(), previous_->level()));
    }
    sinks.push_back(file_sink);
    auto logger = std::make_shared<spdlog::logger>("", sinks.begin(), sinks.end());
    logger->set_level(spdlog::level::debug);
    logger->flush_on(spdlog::level::debug);  // a killed run keeps its log up to the end
    spdlog::set_default_logger(logger);
  }
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;
  ~RunLog() {
    for (std::size_t i = 0; i < sink_levels_.size(); ++i)
      previous_->sinks()[i]->set_level(sink_levels_[i]);
    spdlog::set_default_logger(previous_);
  }

 private:
  std::shared_ptr<spdlog::logger> previous_;
  std::vector<spdlog::level::level_enum> sink_levels_;
};

// CPU time [s] of this process's threads and of its finished, waited-for children (a stage's
// subprocess), user plus system.
double cpu_seconds_so_far() {
  double total = 0.0;
  for (int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage usage{};
    ::getrusage(who, &usage);
    for (const timeval& t : {usage.ru_utime, usage.ru_stime})
      total += double(t.tv_sec) + 1e-6 * double(t.tv_usec);
  }
  return total;
}

std::string config_identity(const RunOptions& options) {
  return options.config_file.empty() ? std::string()
                                     : fs::weakly_canonical(options.config_file).string();
}

// True when the folder holds nothing but (possibly) our lock file.
bool holds_nothing_but_lock(const fs::path& folder) {
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().filename() != kLockName) return false;
  return true;
}

// Whether run.json must be written; InputError when the folder is no run folder of this config.
bool run_record_needed(const RunOptions& options) {
  const fs::path& folder = options.folder;
  const fs::path record = folder / kRunRecordName;
  const std::string config = config_identity(options);
  if (fs::exists(folder) && !fs::is_directory(folder))
    throw InputError(folder.string(), 0, "--out", "exists and is not a folder");
  if (fs::exists(record)) {
    std::string made_by;
    try {
      made_by = read_run_record(record).config;
    } catch (const InputError& e) {
      if (!options.force)
        throw InputError(e.file(), e.line(), e.field(),
                         e.problem() + "; use another --out, or --force to replace the record");
      spdlog::warn("{}: replaced (--force): {}", record.string(), e.what());
      return true;
    }
    if (made_by != config && !options.force)
      throw InputError(record.string(), 0, "config",
                       "this run folder was made by '" + made_by + "', not by '" + config +
                           "'; use another --out, or --force to rerun it with this config");
    return made_by != config;
  }
  if (fs::exists(folder) && !holds_nothing_but_lock(folder) && !options.force) {
    throw InputError(folder.string(), 0, "",
                     "exists, is not empty and is not an imscal run folder (no run.json); use "
                     "another --out, or --force to use it anyway");
  }
  return true;
}

void record_run_folder(const RunOptions& options) {
  write_run_record(options.folder / kRunRecordName,
                   {config_identity(options), options.tool_version});
}

void remove_leftovers(const fs::path& folder) {
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) == 0 || name.rfind(kOldPrefix, 0) == 0) {
      spdlog::info("removing {} (left by an interrupted run)", name);
      fs::remove_all(entry.path());
    }
  }
}

// Moves the finished staging folder to <run>/<stage>: the old folder is first moved aside, so
// that at every instant the visible folder is either the old complete one, none, or the new one.
void commit_stage_folder(const fs::path& staging, const fs::path& target, const fs::path& aside) {
  if (fs::exists(target)) fs::rename(target, aside);
  fs::rename(staging, target);
  std::error_code ignored;
  fs::remove_all(aside, ignored);
}

struct Completed {
  StageStatus status;
  json outputs;
};

}  // namespace

RunSummary run_stages(const std::vector<std::unique_ptr<Stage>>& stages,
                      const RunOptions& options) {
  std::set<std::string> names;
  for (const auto& stage : stages) {
    if (!valid_stage_name(stage->name()) || stage->name() == "run.log" ||
        !names.insert(stage->name()).second)
      throw std::logic_error("run_stages: bad or repeated stage name '" + stage->name() + "'");
  }
  // Checked before anything is created, and again under the lock: a run refused because another
  // holds the folder must not rewrite its run.json.
  run_record_needed(options);
  const fs::path& run_dir = options.folder;
  fs::create_directories(run_dir);
  FolderLock lock(run_dir);
  if (run_record_needed(options)) record_run_folder(options);
  RunLog log(run_dir / "run.log");
  spdlog::info("run in {} ({}, config {}){}", run_dir.string(), options.tool_version,
               options.config_file.string(), options.force ? ", --force: every stage reruns" : "");
  remove_leftovers(run_dir);

  Progress progress;
  RunSummary summary;
  std::map<std::string, Completed> completed;
  bool check_failed = false;
  for (const auto& stage : stages) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string name = stage->name();
    StageRun result;
    result.name = name;
    if (check_failed && !stage->runs_after_failed_check()) {
      spdlog::info("{}: not run (an earlier check failed)", name);
      summary.stages.push_back(result);
      continue;
    }
    const StageInputs declared = stage->inputs();
    json inputs = {
        {"files", json::array()}, {"upstream", json::array()}, {"config", declared.config}};
    for (const auto& [role, file] : declared.files) {
      inputs["files"].push_back({{"role", role},
                                 {"path", fs::absolute(file).lexically_normal().string()},
                                 {"sha256", sha256_hex_of_file(file)}});
    }
    std::vector<std::string> completed_upstream;
    for (const std::string& up : declared.upstream) {
      const auto found = completed.find(up);
      if (found == completed.end()) {
        inputs["upstream"].push_back({{"stage", up}, {"status", "not run"}});
      } else {
        completed_upstream.push_back(up);
        inputs["upstream"].push_back({{"stage", up},
                                      {"status", to_string(found->second.status)},
                                      {"outputs", found->second.outputs}});
      }
    }

    const fs::path stage_dir = run_dir / name;
    const std::optional<json> record = read_json_file(stage_dir / kStageRecordName);
    const bool unchanged = !options.force && record && record->value("inputs", json()) == inputs &&
                           record->value("tool_version", "") == options.tool_version &&
                           record->contains("outputs") &&
                           outputs_intact(stage_dir, (*record)["outputs"]);
    if (unchanged) {
      result.what = StageRun::What::kSkipped;
      result.status =
          record->value("status", "") == "ok" ? StageStatus::kOk : StageStatus::kCheckFailed;
      result.message = record->value("message", "");
      completed[name] = {result.status, (*record)["outputs"]};
      spdlog::info("{}: inputs unchanged since {}, skipped ({}{}{})", name,
                   record->value("finished_utc", "?"), to_string(result.status),
                   result.message.empty() ? "" : ": ", result.message);
    } else {
      spdlog::info("{}: {}", name,
                   options.force ? "rerun (--force)"
                   : record      ? "inputs, version or outputs changed: rerun"
                                 : "no record: run");
      const fs::path staging = run_dir / (kStagingPrefix + name + "-" + std::to_string(::getpid()));
      fs::remove_all(staging);
      fs::create_directories(staging);
      const std::string started = utc_now();
      const double cpu0 = cpu_seconds_so_far();
      StageOutcome outcome;
      try {
        StageWorkspace workspace(staging, run_dir, completed_upstream, name, &progress);
        outcome = stage->run(workspace);
        progress.finish();
      } catch (...) {
        progress.finish();
        std::error_code ignored;
        fs::remove_all(staging, ignored);
        spdlog::error("{}: failed; nothing of it was kept", name);
        throw;
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const json outputs = output_checksums(staging);
      const json stage_record = {{"schema", "imscal-stage-record"},
                                 {"schema_version", 1},
                                 {"stage", name},
                                 {"status", to_string(outcome.status)},
                                 {"message", outcome.message},
                                 {"tool_version", options.tool_version},
                                 {"started_utc", started},
                                 {"finished_utc", utc_now()},
                                 {"seconds", seconds},
                                 {"cpu_seconds", cpu_seconds_so_far() - cpu0},
                                 {"inputs", inputs},
                                 {"outputs", outputs},
                                 {"summary", outcome.summary}};
      write_file_atomically(staging / kStageRecordName,
                            json_text(stage_record, 1, (stage_dir / kStageRecordName).string()));
      commit_stage_folder(staging, stage_dir,
                          run_dir / (kOldPrefix + name + "-" + std::to_string(::getpid())));
      result.what = StageRun::What::kRan;
      result.status = outcome.status;
      result.message = outcome.message;
      completed[name] = {outcome.status, outputs};
      spdlog::info("{}: {} in {:.2f} s{}{}", name, to_string(outcome.status), seconds,
                   outcome.message.empty() ? "" : ": ", outcome.message);
    }
    if (result.status == StageStatus::kCheckFailed) check_failed = true;
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    summary.stages.push_back(result);
  }
  return summary;
}

}  // namespace imscal
