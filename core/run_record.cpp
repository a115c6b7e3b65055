#include "core/run_record.hpp"

#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_fields.hpp"
#include "core/json_output.hpp"

namespace imscal {

namespace {
constexpr const char* kSchema = "imscal-run-folder";
}  // namespace

std::string run_record_text(const RunRecord& record, const std::filesystem::path& target) {
  const nlohmann::json run = {{"schema", kSchema},
                              {"schema_version", 1},
                              {"config", record.config},
                              {"created_by", record.created_by}};
  return json_text(run, 1, target.string());
}

void write_run_record(const std::filesystem::path& file, const RunRecord& record) {
  write_file_atomically(file, run_record_text(record, file));
}

RunRecord read_run_record(const std::filesystem::path& file) {
  const JsonDocument document = read_json_document(file);
  const JsonField root = document.root();
  if (root["schema"].text() != kSchema)
    throw InputError(
        document.file(), 0, "schema",
        "not an imscal run record (schema '" + root["schema"].text() + "', not '" + kSchema + "')");
  document.check_version("schema_version", 1, "an imscal run record");
  return {root["config"].text(), root["created_by"].text()};
}

}  // namespace imscal
