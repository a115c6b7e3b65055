#pragma once
// Fixed-size records of doubles kept in an anonymous temporary file instead of memory: for
// per-instant data that grows with a record and is written once, in order, then read back
// (e.g. the smoother's covariances, ims/zupt_smoother.cpp, which its backward pass reads in
// reverse). The values come back bit for bit. Memory: one block of records (the write buffer,
// then the read cache); the file is deleted when the object goes (std::tmpfile).
#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace imscal {

class RecordFile {
 public:
  // `what` names the data in error messages. Throws std::runtime_error when no temporary file
  // can be made.
  RecordFile(std::size_t values_per_record, std::size_t records_per_block, std::string what);

  // Appends one record of values_per_record() values; only before the first read.
  void append(const double* values);

  // The record at `index` (< size()); the pointer stays valid until the next call.
  const double* record(std::size_t index);

  std::size_t size() const { return records_; }
  std::size_t values_per_record() const { return values_per_record_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  void flush_block();
  void load_block(std::size_t block);

  std::size_t values_per_record_;
  std::size_t records_per_block_;
  std::string what_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::vector<double> buffer_;  // the block being written, then the block last read
  std::size_t records_ = 0;     // appended
  std::size_t written_ = 0;     // records in the file
  bool reading_ = false;
  std::size_t cached_block_ = 0;  // block in buffer_ while reading
};

}  // namespace imscal
