// SpillableVector: against a std::vector given the same operations (the truth), in memory and
// in its temporary file, element bits included; its pages leave resident memory behind a
// reader (the kernel's own count in /proc/self/smaps) and come back with the same bytes.
#include "core/spillable_vector.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using imscal::SpillableVector;

// A record-like sample with an Eigen member (not trivially copyable, as ims::ImuSample).
struct Sample {
  double t_s = 0.0;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
};

Sample sample_of(std::size_t i) {
  // Bits that must survive: fractions, a denormal, -0, infinity.
  return {double(i) / 3.0,
          Eigen::Vector3d(std::ldexp(1.0, -1070) * double(i + 1), -0.0,
                          i % 7 == 0 ? std::numeric_limits<double>::infinity() : 1e300)};
}

template <class A, class B>
bool same_bits(const A& a, const B& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i].t_s, &b[i].t_s, sizeof(double)) != 0 ||
        std::memcmp(a[i].value.data(), b[i].value.data(), 3 * sizeof(double)) != 0)
      return false;
  return true;
}

TEST(SpillableVector, FollowsAVectorInMemoryAndOnFile) {
  std::vector<Sample> truth;
  SpillableVector<Sample> array;
  for (std::size_t i = 0; i < 1000; ++i) {
    truth.push_back(sample_of(i));
    array.push_back(sample_of(i));
  }
  array.spill_to_file();
  ASSERT_TRUE(array.on_file());
  EXPECT_TRUE(same_bits(array, truth));
  // Appending past the file's room grows it (the mapping may move) and keeps the elements.
  for (std::size_t i = 1000; i < 300000; ++i) {
    truth.push_back(sample_of(i));
    array.emplace_back(sample_of(i));
  }
  EXPECT_TRUE(same_bits(array, truth));
  // In place, resized, copied (a copy of a spilled array is spilled), erased (back to memory).
  array[17].t_s = truth[17].t_s = -4.5;
  array.resize(250000);
  truth.resize(250000);
  const SpillableVector<Sample> copy = array;
  EXPECT_TRUE(copy.on_file());
  EXPECT_TRUE(same_bits(copy, truth));
  array.erase(array.begin() + 3, array.begin() + 10);
  truth.erase(truth.begin() + 3, truth.begin() + 10);
  EXPECT_FALSE(array.on_file());
  EXPECT_TRUE(same_bits(array, truth));
  // Inserting in memory returns the first inserted element's place, as std::vector's insert;
  // an empty range at the end returns end() (never dereferenced).
  const Sample extra[2] = {sample_of(7), sample_of(8)};
  EXPECT_EQ(array.insert(array.begin() + 5, extra, extra + 2), array.begin() + 5);
  truth.insert(truth.begin() + 5, extra, extra + 2);
  EXPECT_EQ(array.insert(array.end(), extra, extra), array.end());
  EXPECT_TRUE(same_bits(array, truth));
  array.assign(extra, extra);  // clear, then an empty range at the end
  EXPECT_TRUE(array.empty());
}

// An element of the array appended to it when the file is full: the copy is made before the
// file grows, so it holds the element's bits wherever the mapping moves (as std::vector's
// push_back of its own element).
TEST(SpillableVector, AppendsItsOwnElementWhenTheFileGrows) {
  std::vector<Sample> truth;
  SpillableVector<Sample> array;
  array.push_back(sample_of(1));
  truth.push_back(sample_of(1));
  array.spill_to_file();
  for (int growth = 0; growth < 4; ++growth) {
    while (array.size() < array.capacity()) {
      array.push_back(sample_of(array.size() + 1));
      truth.push_back(sample_of(truth.size() + 1));
    }
    array.push_back(array.front());
    truth.push_back(truth.front());
    array.resize(array.size() + 3, array[1]);
    truth.resize(truth.size() + 3, truth[1]);
  }
  ASSERT_TRUE(array.on_file());
  EXPECT_TRUE(same_bits(array, truth));
}

// The resident kB of the mapping that holds `address`, from /proc/self/smaps.
long resident_kb_of_mapping(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("Rss:", 0) == 0) {
      return std::stol(line.substr(4));
    }
  }
  return -1;
}

TEST(SpillableVector, PagesLeaveResidentMemoryAndComeBackUnchanged) {
  SpillableVector<Sample> array;
  array.spill_to_file();
  for (std::size_t i = 0; i < 400000; ++i) array.push_back(sample_of(i));  // 12.8 MB
  double sum = 0.0;
  for (const Sample& s : array) sum += s.t_s;  // every page touched
  // Released by the background thread within a few periods (a loaded machine: up to 20 s).
  long resident_kb = resident_kb_of_mapping(array.data());
  for (int wait = 0; wait < 200 && resident_kb > 1024; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    resident_kb = resident_kb_of_mapping(array.data());
  }
  EXPECT_GE(resident_kb, 0);
  EXPECT_LE(resident_kb, 1024) << "of " << array.size() * sizeof(Sample) / 1024 << " kB";
  std::vector<Sample> truth;
  for (std::size_t i = 0; i < 400000; ++i) truth.push_back(sample_of(i));
  EXPECT_TRUE(same_bits(array, truth));
  EXPECT_GT(sum, 0.0);
}

}  // namespace
