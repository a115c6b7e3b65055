#include "core/record_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace imscal {

RecordFile::RecordFile(std::size_t values_per_record, std::size_t records_per_block,
                       std::string what)
    : values_per_record_(values_per_record),
      records_per_block_(std::max<std::size_t>(1, records_per_block)),
      what_(std::move(what)),
      file_(std::tmpfile()) {
  if (!file_)
    throw std::runtime_error("cannot create a temporary file for " + what_ + ": " +
                             std::strerror(errno));
  buffer_.reserve(values_per_record_ * records_per_block_);
}

void RecordFile::append(const double* values) {
  if (reading_) throw std::logic_error("RecordFile::append after a read (" + what_ + ")");
  buffer_.insert(buffer_.end(), values, values + values_per_record_);
  ++records_;
  if (records_ - written_ == records_per_block_) flush_block();
}

void RecordFile::flush_block() {
  const std::size_t count = records_ - written_;
  if (count == 0) return;
  if (std::fwrite(buffer_.data(), sizeof(double) * values_per_record_, count, file_.get()) != count)
    throw std::runtime_error("cannot write the temporary file for " + what_ +
                             " (disk full?): " + std::strerror(errno));
  written_ = records_;
  buffer_.clear();
}

void RecordFile::load_block(std::size_t block) {
  const std::size_t first = block * records_per_block_;
  const std::size_t count = std::min(records_per_block_, records_ - first);
  buffer_.resize(values_per_record_ * count);
  const long offset = long(first * values_per_record_ * sizeof(double));
  if (std::fseek(file_.get(), offset, SEEK_SET) != 0 ||
      std::fread(buffer_.data(), sizeof(double) * values_per_record_, count, file_.get()) != count)
    throw std::runtime_error("cannot read back the temporary file for " + what_ + ": " +
                             std::strerror(errno));
  cached_block_ = block;
}

const double* RecordFile::record(std::size_t index) {
  if (index >= records_) throw std::out_of_range("RecordFile::record (" + what_ + ")");
  if (!reading_) {
    flush_block();
    std::fflush(file_.get());
    reading_ = true;
    load_block(index / records_per_block_);
  } else if (index / records_per_block_ != cached_block_) {
    load_block(index / records_per_block_);
  }
  return buffer_.data() + (index % records_per_block_) * values_per_record_;
}

}  // namespace imscal
