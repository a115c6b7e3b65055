// Side by side: reading one RSI controller datagram (IPOC, ASPos A1..A6, AIPos A1..A6) with the
// project's parser (online/rsi_datagram.hpp) and with tinyxml2 (Debian's libtinyxml2-dev, one
// XMLDocument reused for every datagram, as a server would), on the same 10^5 datagrams: time
// per datagram (median, 99.9th percentile) and heap allocations per datagram (counted by
// replacing operator new and, for tinyxml2's C allocations, by its own use of new). Both must
// read the same values. The comparison behind docs/decisions/0023.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <benchmark/benchmark.h>
#include <tinyxml2.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "online/controller_emulator.hpp"
#include "online/rsi_datagram.hpp"
#include "tests/support/allocation_counter.hpp"

namespace {

using namespace imscal::online;

constexpr std::size_t kDatagrams = 100000;

std::vector<std::string> datagrams() {
  std::vector<std::string> out(kDatagrams);
  std::array<char, 1024> buffer{};
  for (std::size_t k = 0; k < kDatagrams; ++k) {
    std::array<double, kRsiAxes> q{};
    for (int a = 0; a < kRsiAxes; ++a) q[std::size_t(a)] = 90.0 * std::sin(0.001 * k + a);
    const int n = write_rsi_robot_datagram("KUKA", q, 4 * k, buffer.data(), int(buffer.size()));
    out[k].assign(buffer.data(), std::size_t(n));
  }
  return out;
}

bool read_axes(const tinyxml2::XMLElement* e, std::array<double, kRsiAxes>* out) {
  static const char* const names[kRsiAxes] = {"A1", "A2", "A3", "A4", "A5", "A6"};
  for (int a = 0; a < kRsiAxes; ++a)
    if (e == nullptr || e->QueryDoubleAttribute(names[a], &(*out)[std::size_t(a)]) != 0)
      return false;
  return true;
}

// tinyxml2's reading of the same fields; false when a field is missing.
bool tinyxml2_parse(tinyxml2::XMLDocument& doc, const std::string& text, RsiRobotDatagram* d) {
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) return false;
  const tinyxml2::XMLElement* rob = doc.FirstChildElement("Rob");
  if (rob == nullptr) return false;
  const tinyxml2::XMLElement* ipoc = rob->FirstChildElement("IPOC");
  if (ipoc == nullptr || ipoc->QueryUnsigned64Text(&d->ipoc) != tinyxml2::XML_SUCCESS) return false;
  d->has_actual = read_axes(rob->FirstChildElement("AIPos"), &d->actual_deg);
  return read_axes(rob->FirstChildElement("ASPos"), &d->setpoint_deg);
}

template <class Parse>
void time_parser(benchmark::State& state, Parse parse) {
  const std::vector<std::string> text = datagrams();
  std::vector<double> ns(kDatagrams);
  long allocations = 0;
  double checksum = 0.0;
  for (auto _ : state) {
    for (std::size_t k = 0; k < kDatagrams; ++k) {
      RsiRobotDatagram d;
      const long before = imscal::test_support::g_allocations.load(std::memory_order_relaxed);
      const auto begin = std::chrono::steady_clock::now();
      const bool ok = parse(text[k], &d);
      const auto end = std::chrono::steady_clock::now();
      allocations += imscal::test_support::g_allocations.load(std::memory_order_relaxed) - before;
      if (!ok || d.ipoc != 4 * k) state.SkipWithError("a datagram was not read");
      checksum += d.setpoint_deg[0] + d.actual_deg[5];
      ns[k] = std::chrono::duration<double, std::nano>(end - begin).count();
    }
  }
  std::sort(ns.begin(), ns.end());
  state.counters["median_ns"] = ns[kDatagrams / 2];
  state.counters["p99.9_ns"] = ns[std::size_t(kDatagrams * 0.999)];
  state.counters["allocations_per_datagram"] = double(allocations) / double(kDatagrams);
  state.counters["checksum"] = checksum;  // equal for both parsers
}

void BM_ImscalRsiParser(benchmark::State& state) {
  time_parser(state, [](const std::string& text, RsiRobotDatagram* d) {
    return parse_rsi_robot_datagram(text, d) == RsiParseError::kNone;
  });
}
BENCHMARK(BM_ImscalRsiParser)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_Tinyxml2ReusedDocument(benchmark::State& state) {
  tinyxml2::XMLDocument doc;
  time_parser(state, [&doc](const std::string& text, RsiRobotDatagram* d) {
    return tinyxml2_parse(doc, text, d);
  });
}
BENCHMARK(BM_Tinyxml2ReusedDocument)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
