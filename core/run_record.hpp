#pragma once
// run.json, the record of a run folder (core/run_stage.hpp; datasets/FORMAT.md): which config
// made the folder and which imscal created it. A later run in the same folder reads it back to
// refuse a folder that another config made.
#include <filesystem>
#include <string>

namespace imscal {

struct RunRecord {
  std::string config;      // the canonical path of the config that made the folder
  std::string created_by;  // "imscal 0.1.0"
};

// The file's content: {"schema": "imscal-run-folder", "schema_version": 1, "config", "created_by"}.
std::string run_record_text(const RunRecord& record, const std::filesystem::path& target);

// Writes `file` atomically (core/atomic_file.hpp).
void write_run_record(const std::filesystem::path& file, const RunRecord& record);

// Reads `file`; InputError naming the file and the field for a file that is not JSON, repeats a
// key, is not a run record of schema version 1, or lacks a field or holds one of another type.
RunRecord read_run_record(const std::filesystem::path& file);

}  // namespace imscal
