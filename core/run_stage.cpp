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
#include <condition_variable>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/run_record.hpp"
#include "core/sha256.hpp"
#include "core/subprocess.hpp"

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

// A terminal sink whose lines go above the progress line (Progress::above_line), so that the
// log of one stage never lands inside another stage's progress figure.
class AboveProgressSink final : public spdlog::sinks::sink {
 public:
  AboveProgressSink(spdlog::sink_ptr terminal, Progress& progress)
      : terminal_(std::move(terminal)), progress_(progress) {
    set_level(terminal_->level());
  }
  void log(const spdlog::details::log_msg& msg) override {
    progress_.above_line([&] { terminal_->log(msg); });
  }
  void flush() override { terminal_->flush(); }
  void set_pattern(const std::string& pattern) override { terminal_->set_pattern(pattern); }
  void set_formatter(std::unique_ptr<spdlog::formatter> formatter) override {
    terminal_->set_formatter(std::move(formatter));
  }

 private:
  spdlog::sink_ptr terminal_;
  Progress& progress_;
};

// Adds <run>/run.log to the default logger for the lifetime of the object; the terminal's lines
// go above the progress line.
class RunLog {
 public:
  RunLog(const fs::path& file, Progress& progress) : previous_(spdlog::default_logger()) {
    auto file_sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(file.string(), false);
    file_sink->set_pattern("%Y-%m-%dT%H:%M:%S.%e %l %v");
    file_sink->set_level(spdlog::level::debug);
    std::vector<spdlog::sink_ptr> sinks;
    // The terminal keeps the level it had; the log file gets debug messages too.
    for (const auto& sink : previous_->sinks()) {
      sink_levels_.push_back(sink->level());
      sink->set_level(std::max(sink->level(), previous_->level()));
      sinks.push_back(std::make_shared<AboveProgressSink>(sink, progress));
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

// What a stage's thread hands back: its line of the summary and its outputs, or its exception.
struct Finished {
  StageRun run;
  Completed completed{StageStatus::kOk, json::array()};
  std::exception_ptr error;
};

// CPU time [s] of the calling thread and of the children it ran and waited for: one stage's,
// while other stages run on other threads.
double thread_cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_THREAD, &usage);
  double total = children_cpu_seconds_of_this_thread();
  for (const timeval& t : {usage.ru_utime, usage.ru_stime})
    total += double(t.tv_sec) + 1e-6 * double(t.tv_usec);
  return total;
}

json input_record(const StageInputs& declared, json upstream) {
  json inputs = {
      {"files", json::array()}, {"upstream", std::move(upstream)}, {"config", declared.config}};
  for (const auto& [role, file] : declared.files) {
    inputs["files"].push_back({{"role", role},
                               {"path", fs::absolute(file).lexically_normal().string()},
                               {"sha256", sha256_hex_of_file(file)}});
  }
  return inputs;
}

// The recorded result, when the stage's record matches these inputs and its outputs are intact.
std::optional<Finished> skipped(const std::string& name, const fs::path& stage_dir,
                                const std::optional<json>& record, const json& inputs,
                                const RunOptions& options) {
  if (options.force || !record || record->value("inputs", json()) != inputs ||
      record->value("tool_version", "") != options.tool_version || !record->contains("outputs") ||
      !outputs_intact(stage_dir, (*record)["outputs"]))
    return std::nullopt;
  Finished f;
  f.run.name = name;
  f.run.what = StageRun::What::kSkipped;
  f.run.status = record->value("status", "") == "ok" ? StageStatus::kOk : StageStatus::kCheckFailed;
  f.run.message = record->value("message", "");
  f.completed = {f.run.status, (*record)["outputs"]};
  spdlog::info("{}: inputs unchanged since {}, skipped ({}{}{})", name,
               record->value("finished_utc", "?"), to_string(f.run.status),
               f.run.message.empty() ? "" : ": ", f.run.message);
  return f;
}

// A stage that is about to start, with what the scheduler resolved for it.
struct StageJob {
  Stage* stage;
  StageInputs declared;
  json upstream;  // the inputs' "upstream" entries
  std::vector<std::string> completed_upstream;
};

// Runs the stage into its staging folder and commits it; the staging folder is removed when the
// stage throws.
Finished execute(const StageJob& job, const json& inputs, const RunOptions& options,
                 Progress& progress, std::chrono::steady_clock::time_point t0) {
  const std::string name = job.stage->name();
  const fs::path& run_dir = options.folder;
  const fs::path stage_dir = run_dir / name;
  const fs::path staging = run_dir / (kStagingPrefix + name + "-" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  const std::string started = utc_now();
  const double cpu0 = thread_cpu_seconds();
  StageOutcome outcome;
  try {
    StageWorkspace workspace(staging, run_dir, job.completed_upstream, name, &progress);
    outcome = job.stage->run(workspace);
    progress.finish(name);
  } catch (...) {
    progress.finish(name);
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
                             {"cpu_seconds", thread_cpu_seconds() - cpu0},
                             {"inputs", inputs},
                             {"outputs", outputs},
                             {"summary", outcome.summary}};
  write_file_atomically(staging / kStageRecordName,
                        json_text(stage_record, 1, (stage_dir / kStageRecordName).string()));
  commit_stage_folder(staging, stage_dir,
                      run_dir / (kOldPrefix + name + "-" + std::to_string(::getpid())));
  spdlog::info("{}: {} in {:.2f} s{}{}", name, to_string(outcome.status), seconds,
               outcome.message.empty() ? "" : ": ", outcome.message);
  Finished f;
  f.run = {name, StageRun::What::kRan, outcome.status, outcome.message, 0.0};
  f.completed = {outcome.status, outputs};
  return f;
}

// One stage on its thread: skipped when unchanged, else run and committed.
Finished process_stage(const StageJob& job, const RunOptions& options, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string name = job.stage->name();
  const json inputs = input_record(job.declared, job.upstream);
  const fs::path stage_dir = options.folder / name;
  const std::optional<json> record = read_json_file(stage_dir / kStageRecordName);
  std::optional<Finished> result = skipped(name, stage_dir, record, inputs, options);
  if (!result) {
    spdlog::info("{}: {}", name,
                 options.force ? "rerun (--force)"
                 : record      ? "inputs, version or outputs changed: rerun"
                               : "no record: run");
    result = execute(job, inputs, options, progress, t0);
  }
  result->run.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return std::move(*result);
}

}  // namespace

namespace {

// Starts each stage on its own thread once the earlier stages it waits for have ended, at most
// `max_parallel` at a time; collects the results in chain order.
class StageScheduler {
 public:
  StageScheduler(const std::vector<std::unique_ptr<Stage>>& stages, const RunOptions& options,
                 Progress& progress)
      : stages_(stages), options_(options), progress_(progress), state_(stages.size(), kWaiting) {
    max_parallel_ = options.max_parallel_stages != 0
                        ? options.max_parallel_stages
                        : std::max(1u, std::thread::hardware_concurrency());
    for (const auto& stage : stages) {
      StageRun not_run;
      not_run.name = stage->name();
      summary_.stages.push_back(not_run);
    }
  }
  StageScheduler(const StageScheduler&) = delete;
  StageScheduler& operator=(const StageScheduler&) = delete;
  // A throw on this thread still waits for the stages running (their threads use this object).
  ~StageScheduler() {
    for (std::thread& t : threads_) t.join();
  }

  RunSummary run() {
    for (;;) {
      if (!error_) start_ready_stages();
      if (running_ == 0) break;
      std::vector<std::pair<std::size_t, Finished>> ended;
      {
        std::unique_lock lock(mutex_);
        ended_cv_.wait(lock, [&] { return !ended_.empty(); });
        ended.swap(ended_);
      }
      for (auto& [index, finished] : ended) record(index, std::move(finished));
    }
    if (error_) std::rethrow_exception(error_);
    return summary_;
  }

 private:
  enum State { kWaiting, kRunning, kDone };

  bool check_failed_before(std::size_t index) const {
    for (std::size_t j = 0; j < index; ++j)
      if (state_[j] == kDone && summary_.stages[j].what != StageRun::What::kNotRun &&
          summary_.stages[j].status == StageStatus::kCheckFailed)
        return true;
    return false;
  }

  // Whether every earlier stage this one waits for has ended.
  bool may_start(std::size_t index, const StageInputs& declared) const {
    const Stage& stage = *stages_[index];
    for (std::size_t j = 0; j < index; ++j) {
      const std::string& earlier = summary_.stages[j].name;
      const bool waits = stage.runs_after_failed_check() || stages_[j]->gates_later_stages() ||
                         std::find(declared.upstream.begin(), declared.upstream.end(), earlier) !=
                             declared.upstream.end();
      if (waits && state_[j] != kDone) return false;
    }
    return true;
  }

  void start_ready_stages() {
    for (std::size_t i = 0; i < stages_.size() && running_ < max_parallel_; ++i) {
      if (state_[i] != kWaiting) continue;
      if (check_failed_before(i) && !stages_[i]->runs_after_failed_check()) {
        spdlog::info("{}: not run (an earlier check failed)", summary_.stages[i].name);
        state_[i] = kDone;
        continue;
      }
      StageInputs declared = stages_[i]->inputs();
      if (may_start(i, declared)) start(i, std::move(declared));
    }
  }

  // The inputs' upstream entries: the earlier stages' output checksums, or "not run".
  StageJob job_for(std::size_t index, StageInputs declared) const {
    StageJob job{stages_[index].get(), std::move(declared), json::array(), {}};
    for (const std::string& up : job.declared.upstream) {
      const auto found = completed_.find(up);
      if (found == completed_.end()) {
        job.upstream.push_back({{"stage", up}, {"status", "not run"}});
      } else {
        job.completed_upstream.push_back(up);
        job.upstream.push_back({{"stage", up},
                                {"status", to_string(found->second.status)},
                                {"outputs", found->second.outputs}});
      }
    }
    return job;
  }

  void start(std::size_t index, StageInputs declared) {
    state_[index] = kRunning;
    ++running_;
    threads_.emplace_back([this, index, job = job_for(index, std::move(declared))] {
      Finished finished;
      try {
        finished = process_stage(job, options_, progress_);
      } catch (...) {
        finished.error = std::current_exception();
      }
      const std::lock_guard lock(mutex_);
      ended_.emplace_back(index, std::move(finished));
      ended_cv_.notify_one();
    });
  }

  void record(std::size_t index, Finished finished) {
    --running_;
    state_[index] = kDone;
    if (finished.error) {
      // The first stage in chain order that threw is the one reported.
      if (!error_ || index < error_index_) {
        error_ = finished.error;
        error_index_ = index;
      }
      return;
    }
    completed_[summary_.stages[index].name] = finished.completed;
    summary_.stages[index] = std::move(finished.run);
  }

  const std::vector<std::unique_ptr<Stage>>& stages_;
  const RunOptions& options_;
  Progress& progress_;
  unsigned max_parallel_ = 1;
  std::vector<State> state_;
  RunSummary summary_;
  // Only the stages that completed (ran or skipped) earlier in this run; a stage started reads
  // nothing else, and they are all earlier in the chain (upstream stages are never later ones).
  std::map<std::string, Completed> completed_;
  unsigned running_ = 0;
  std::exception_ptr error_;
  std::size_t error_index_ = 0;
  std::mutex mutex_;  // guards ended_
  std::condition_variable ended_cv_;
  std::vector<std::pair<std::size_t, Finished>> ended_;
  std::vector<std::thread> threads_;
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
  Progress progress(Progress::Stages::kConcurrent);
  RunLog log(run_dir / "run.log", progress);
  spdlog::info("run in {} ({}, config {}){}", run_dir.string(), options.tool_version,
               options.config_file.string(), options.force ? ", --force: every stage reruns" : "");
  remove_leftovers(run_dir);
  StageScheduler scheduler(stages, options, progress);
  return scheduler.run();
}

}  // namespace imscal
