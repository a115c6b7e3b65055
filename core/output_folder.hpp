#pragma once
// A command's set of output files, written all or nothing: every file is first written into a
// hidden staging folder inside the output folder, and only when all of them are complete are they
// renamed into place. An error or an interruption before commit() leaves the output folder as it
// was (the staging folder is removed; a crash leaves only the hidden `.imscal-staging-*`).
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"

namespace imscal {

// Creates an output folder (and its parents). InputError when the path names a file (a mistake on
// the command line, exit 2 in every command); std::runtime_error with the system's reason when
// the folder cannot be created.
void create_output_folder(const std::filesystem::path& folder);

// A command's single output file, checked before any work: InputError (exit 2) when the path
// names a folder, or names an existing file and `overwrite` is kRefuse; a missing folder of the
// file is created (as every command creates its output folder). The file itself is written later
// with write_file_atomically.
void prepare_output_file(const std::filesystem::path& file, Overwrite overwrite);

class OutputFolder {
 public:
  // `outputs`: the files this command will write, relative to `folder`. With Overwrite::kRefuse
  // an InputError naming the first existing one is thrown here, before any work is done.
  OutputFolder(std::filesystem::path folder, std::vector<std::filesystem::path> outputs,
               Overwrite overwrite);
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  // Where to write `relative` (one of the declared outputs) now; its parent folder exists.
  std::filesystem::path staged(const std::filesystem::path& relative) const;
  // Moves every declared output into place; throws if one was not written.
  void commit();

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
  std::filesystem::path staging_;
  std::vector<std::filesystem::path> outputs_;
  bool committed_ = false;
};

}  // namespace imscal
