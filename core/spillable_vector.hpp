#pragma once
// A std::vector-like array of samples that can move to a temporary file (core/spill_mapping.hpp)
// when asked: for the records a command holds whole while its stages read them by interval
// (the IMS record and the robot log in `imscal calibrate`), so that the resident memory does
// not grow with the record. In memory (the default) it is a std::vector; after spill_to_file()
// the elements live in a mapped temporary file, read and written in place with the same bytes
// (the element access, views and iterators are the same pointers), and appending grows the file.
// Growing may move the elements, as a vector's reallocation does; nothing else invalidates a
// pointer. A copy of a spilled array is spilled too. The elements are relocated bytewise on
// growth (mremap), hence trivially destructible types whose bytes are the whole object only.
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/spill_mapping.hpp"

namespace imscal {

template <class T>
class SpillableVector {
  static_assert(std::is_trivially_destructible_v<T>, "elements are dropped with their file");

 public:
  using value_type = T;
  using size_type = std::size_t;
  using difference_type = std::ptrdiff_t;
  using reference = T&;
  using const_reference = const T&;
  using pointer = T*;
  using const_pointer = const T*;
  using iterator = T*;
  using const_iterator = const T*;

  SpillableVector() = default;
  SpillableVector(std::vector<T> values) : memory_(std::move(values)) {}  // NOLINT
  SpillableVector(std::initializer_list<T> values) : memory_(values) {}
  SpillableVector(size_type n, const T& value = T()) : memory_(n, value) {}
  template <class It, class = decltype(*std::declval<It>())>
  SpillableVector(It first, It last) : memory_(first, last) {}
  SpillableVector(const SpillableVector& other) : memory_(other.memory_) {
    if (other.on_file()) append_to_file(other.begin(), other.end());
  }
  SpillableVector(SpillableVector&&) noexcept = default;
  SpillableVector& operator=(const SpillableVector& other) {
    if (this != &other) *this = SpillableVector(other);
    return *this;
  }
  SpillableVector& operator=(SpillableVector&&) noexcept = default;

  // Moves the elements to a temporary file (no-op if they are there). Throws
  // std::runtime_error when no file can be made.
  void spill_to_file() {
    if (on_file()) return;
    std::vector<T> values = std::move(memory_);
    memory_ = {};
    file_ = std::make_unique<File>();
    append_to_file(values.data(), values.data() + values.size());
  }
  bool on_file() const { return file_ != nullptr; }

  size_type size() const { return on_file() ? file_->size : memory_.size(); }
  bool empty() const { return size() == 0; }
  size_type capacity() const {
    return on_file() ? file_->mapping.capacity() / sizeof(T) : memory_.capacity();
  }
  T* data() { return on_file() ? file_elements() : memory_.data(); }
  const T* data() const { return on_file() ? file_elements() : memory_.data(); }
  T* begin() { return data(); }
  T* end() { return data() + size(); }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size(); }
  const T* cbegin() const { return begin(); }
  const T* cend() const { return end(); }
  auto rbegin() const { return std::reverse_iterator<const T*>(end()); }
  auto rend() const { return std::reverse_iterator<const T*>(begin()); }
  T& operator[](size_type i) { return data()[i]; }
  const T& operator[](size_type i) const { return data()[i]; }
  T& at(size_type i) { return i < size() ? data()[i] : throw std::out_of_range("at"); }
  const T& at(size_type i) const { return i < size() ? data()[i] : throw std::out_of_range("at"); }
  T& front() { return data()[0]; }
  const T& front() const { return data()[0]; }
  T& back() { return data()[size() - 1]; }
  const T& back() const { return data()[size() - 1]; }

  void reserve(size_type n) {
    if (!on_file()) return memory_.reserve(n);
    if (n > capacity()) file_->mapping.reserve(n * sizeof(T), "a record's samples");
  }
  void push_back(const T& value) { emplace_back(value); }
  template <class... Args>
  T& emplace_back(Args&&... args) {
    if (!on_file()) return memory_.emplace_back(std::forward<Args>(args)...);
    // Made before growing: an argument may be an element of this array, which growing moves.
    T value(std::forward<Args>(args)...);
    if (size() == capacity()) reserve(std::max<size_type>(2 * size(), 1024));
    T* at_end = ::new (static_cast<void*>(end())) T(std::move(value));
    ++file_->size;
    return *at_end;
  }
  void pop_back() { resize(size() - 1); }
  void clear() { resize(0); }
  void resize(size_type n) { resize(n, T()); }
  void resize(size_type n, const T& value) {
    if (!on_file()) return memory_.resize(n, value);
    const T fill = value;  // before growing: `value` may be an element of this array
    reserve(n);
    std::uninitialized_fill(end(), data() + std::max(n, size()), fill);
    file_->size = n;
  }
  void shrink_to_fit() {
    if (!on_file()) memory_.shrink_to_fit();
  }
  template <class It>
  void assign(It first, It last) {
    clear();
    insert(end(), first, last);
  }
  // Inserting or erasing inside the array moves it back into memory first (the readers of
  // records append only).
  template <class It>
  T* insert(const T* position, It first, It last) {
    const difference_type at = position - begin();
    if (on_file() && position == end()) {
      for (; first != last; ++first) emplace_back(*first);
      return begin() + at;
    }
    to_memory();
    // By position, not by dereferencing: an empty range inserted at the end returns end().
    const auto inserted = memory_.insert(memory_.begin() + at, first, last);
    return memory_.data() + (inserted - memory_.begin());
  }
  T* insert(const T* position, const T& value) { return insert(position, &value, &value + 1); }
  T* erase(const T* first, const T* last) {
    const difference_type at = first - begin(), count = last - first;
    to_memory();
    return memory_.data() +
           (memory_.erase(memory_.begin() + at, memory_.begin() + at + count) - memory_.begin());
  }
  T* erase(const T* position) { return erase(position, position + 1); }

  friend bool operator==(const SpillableVector& a, const SpillableVector& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  }

 private:
  struct File {
    SpillMapping mapping;
    size_type size = 0;
  };
  // The file's elements (std::launder: they were made by placement new in the mapping, and
  // launder may only see a live object, so not when there is none).
  T* file_elements() const {
    T* first = reinterpret_cast<T*>(file_->mapping.data());
    return file_->size == 0 ? first : std::launder(first);
  }
  void append_to_file(const T* first, const T* last) {
    if (!on_file()) file_ = std::make_unique<File>();
    reserve(size() + size_type(last - first));
    std::uninitialized_copy(first, last, end());
    file_->size += size_type(last - first);
  }
  void to_memory() {
    if (!on_file()) return;
    memory_.assign(begin(), end());
    file_.reset();
  }

  std::vector<T> memory_;
  std::unique_ptr<File> file_;  // set: the elements are in the file
};

}  // namespace imscal
