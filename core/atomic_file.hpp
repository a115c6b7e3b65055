#pragma once
// Atomic output files: everything is written to a temporary file beside the target and renamed
// onto it only when complete, so a reader never sees a half-written output and an interrupted
// run leaves the previous file (or none) in place.
#include <filesystem>
#include <fstream>
#include <string_view>

namespace imscal {

enum class Overwrite { kRefuse, kAllow };

class AtomicFile {
 public:
  // Throws std::runtime_error if the target exists and overwrite is kRefuse, or if the temporary
  // file cannot be created.
  explicit AtomicFile(std::filesystem::path target, Overwrite overwrite = Overwrite::kAllow,
                      bool binary = false);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // removes the temporary file unless commit() succeeded

  std::ofstream& stream() { return out_; }
  const std::filesystem::path& target() const { return target_; }

  // Flushes, syncs to disk and renames onto the target. Throws on any I/O failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  std::ofstream out_;
  Overwrite overwrite_;
  bool committed_ = false;
};

// OutputFolder stages a command's outputs in <folder>/.imscal-staging-<pid>/ (output_folder.hpp).
inline constexpr std::string_view kStagingFolderPrefix = ".imscal-staging-";

// The path a staged output will have once published (the staging folder left out), for messages:
// the user looks for the target, never for a temporary file.
std::filesystem::path published_path(const std::filesystem::path& path);

// Convenience: the whole content at once.
void write_file_atomically(const std::filesystem::path& target, std::string_view content,
                           Overwrite overwrite = Overwrite::kAllow);

}  // namespace imscal
