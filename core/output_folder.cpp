#include "core/output_folder.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <stdexcept>
#include <system_error>

#include "core/input_error.hpp"

namespace imscal {

namespace fs = std::filesystem;

// The output folder and the staging folder inside it: an existing file of that name is a
// mistake on the command line (InputError), a folder the system refuses to create an I/O failure
// with its reason.
void create_output_folder(const fs::path& folder) {
  std::error_code error;
  if (fs::exists(folder, error) && !fs::is_directory(folder, error)) {
    throw InputError(folder.string(), 0, "--out",
                     "is a file, not a folder; --out names the folder for the outputs");
  }
  fs::create_directories(folder, error);
  if (error) {
    throw std::runtime_error(
        fmt::format("{}: cannot create the output folder: {}", folder.string(), error.message()));
  }
}

void prepare_output_file(const fs::path& file, Overwrite overwrite) {
  std::error_code error;
  if (fs::is_directory(file, error)) {
    throw InputError(file.string(), 0, "--out",
                     "is a folder, not a file; --out names the output file");
  }
  if (overwrite == Overwrite::kRefuse && fs::exists(file, error)) {
    throw InputError(file.string(), 0, "--out", "exists already (use --force to replace it)");
  }
  if (file.has_parent_path()) create_output_folder(file.parent_path());
}

OutputFolder::OutputFolder(fs::path folder, std::vector<fs::path> outputs, Overwrite overwrite)
    : folder_(std::move(folder)), outputs_(std::move(outputs)) {
  for (const fs::path& relative : outputs_) {
    if (relative.is_absolute() || relative.empty()) {
      throw std::invalid_argument("OutputFolder: outputs must be relative paths");
    }
    const fs::path target = folder_ / relative;
    if (overwrite == Overwrite::kRefuse && fs::exists(target)) {
      throw InputError(target.string(), 0, "", "exists already (use --force to replace it)");
    }
  }
  create_output_folder(folder_);
  staging_ = folder_ / (std::string(kStagingFolderPrefix) + std::to_string(::getpid()));
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
  create_output_folder(staging_);
}

OutputFolder::~OutputFolder() {
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

fs::path OutputFolder::staged(const fs::path& relative) const {
  if (std::find(outputs_.begin(), outputs_.end(), relative) == outputs_.end()) {
    throw std::logic_error("OutputFolder: '" + relative.string() + "' was not declared");
  }
  const fs::path path = staging_ / relative;
  fs::create_directories(path.parent_path());
  return path;
}

void OutputFolder::commit() {
  for (const fs::path& relative : outputs_) {
    if (!fs::is_regular_file(staging_ / relative)) {
      throw std::logic_error("OutputFolder: '" + relative.string() + "' was not written");
    }
  }
  // A target that is a folder would stop the renames half way: refused before the first.
  for (const fs::path& relative : outputs_) {
    std::error_code error;
    if (fs::is_directory(folder_ / relative, error))
      throw InputError((folder_ / relative).string(), 0, "",
                       "is a folder; an output file of this name cannot replace it");
  }
  // Renames within one file system are atomic per file; the set is complete before the first.
  for (const fs::path& relative : outputs_) {
    const fs::path target = folder_ / relative;
    fs::create_directories(target.parent_path());
    fs::rename(staging_ / relative, target);
  }
  committed_ = true;
}

}  // namespace imscal
