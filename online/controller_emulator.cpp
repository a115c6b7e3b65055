#include "online/controller_emulator.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <thread>

#include "core/units.hpp"
#include "online/egm_codec.hpp"

namespace imscal::online {
namespace {

using Clock = std::chrono::steady_clock;

struct Answer {
  std::uint64_t ipoc = 0;
  std::array<double, kRsiAxes> value_deg{};
};

// The emulator's reading of the server's answer (its own format: AKorr A1..A6 and IPOC).
bool read_answer(std::string_view text, Answer* out) {
  const std::size_t korr = text.find("<AKorr");
  const std::size_t ipoc = text.find("<IPOC>");
  if (korr == std::string_view::npos || ipoc == std::string_view::npos) return false;
  for (int a = 0; a < kRsiAxes; ++a) {
    const std::string key = " A" + std::to_string(a + 1) + "=\"";
    const std::size_t at = text.find(key, korr);
    if (at == std::string_view::npos) return false;
    const char* begin = text.data() + at + key.size();
    const auto [end, ec] =
        std::from_chars(begin, text.data() + text.size(), out->value_deg[std::size_t(a)]);
    if (ec != std::errc() || end == text.data() + text.size() || *end != '"') return false;
  }
  const char* begin = text.data() + ipoc + 6;
  const auto [end, ec] = std::from_chars(begin, text.data() + text.size(), out->ipoc);
  return ec == std::errc() && end != text.data() + text.size() && *end == '<';
}

class Emulator {
 public:
  Emulator(UdpSocket& socket, const UdpPeer& server, const EmulatorOptions& options,
           const std::vector<std::array<double, kRsiAxes>>& setpoint_rad)
      : socket_(socket), server_(server), options_(options), setpoint_rad_(setpoint_rad) {
    const std::size_t cycles = setpoint_rad.size();
    run_.correction_rad.resize(cycles);
    run_.answered.assign(cycles, false);
    run_.latency_s.assign(cycles, 0.0);
    sent_at_.resize(cycles);
  }

  void send(std::size_t k, const std::array<double, kRsiAxes>& q_rad, InjectedFault* fault) {
    std::array<double, kRsiAxes> q_deg{};
    for (int a = 0; a < kRsiAxes; ++a) q_deg[std::size_t(a)] = q_rad[std::size_t(a)] * kDegPerRad;
    const InjectedFault kind = fault != nullptr ? *fault : InjectedFault::kDrop;
    if (kind == InjectedFault::kNaN) q_deg[0] = std::numeric_limits<double>::quiet_NaN();
    if (kind == InjectedFault::kJump) q_deg[0] += options_.jump_deg;
    const bool unknown = kind == InjectedFault::kUnknownRobot;
    const int n = options_.protocol == ControllerProtocol::kEgm
                      ? write_egm(k, q_deg, unknown)
                      : write_rsi_robot_datagram(unknown ? "UNKNOWN" : options_.robot_type, q_deg,
                                                 ipoc(k), buffer_.data(), int(buffer_.size()));
    sent_at_[k] = Clock::now();
    if (n <= 0 || !socket_.send(buffer_.data(), n, server_))
      throw std::runtime_error("emulator: cannot send a datagram");
  }

  // EGM: the robot's measured joints (a 7-axis robot when `unknown`), planned the same, motors on.
  int write_egm(std::size_t k, const std::array<double, kRsiAxes>& q_deg, bool unknown) {
    EgmRobotDatagram d;
    d.seqno = std::uint32_t(ipoc(k));
    d.tm_ms = std::uint32_t(std::llround(double(k) * options_.cycle_s * 1e3));
    d.feedback_joints = unknown ? kEgmAxes + 1 : kEgmAxes;
    d.planned_joints = kEgmAxes;
    for (int a = 0; a < kEgmAxes; ++a) {
      d.feedback_deg[std::size_t(a)] = q_deg[std::size_t(a)];
      d.planned_deg[std::size_t(a)] = setpoint_rad_[k][std::size_t(a)] * kDegPerRad;
    }
    d.motors = EgmMotors::kOn;
    return codec_.write_robot(d, buffer_.data(), int(buffer_.size()));
  }

  void send_malformed(std::size_t k) {
    if (options_.protocol == ControllerProtocol::kEgm) {
      // A header field whose length runs past the datagram's end.
      const std::string broken("\x0a\x10\x08\x01\x10", 5);
      if (!socket_.send(broken.data(), int(broken.size()), server_))
        throw std::runtime_error("emulator: cannot send a datagram");
      return;
    }
    const std::string broken = "<Rob Type=\"" + options_.robot_type + "\"><ASPos A1=\"1\"/><IPOC>" +
                               std::to_string(ipoc(k)) + "</IPC></Rob>";
    if (!socket_.send(broken.data(), int(broken.size()), server_))
      throw std::runtime_error("emulator: cannot send a datagram");
  }

  // Reads answers until `expected` of them came or the timeout passed.
  void collect(int expected) {
    const Clock::time_point deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(options_.answer_timeout_s));
    for (int got = 0; got < expected;) {
      const double left_s = std::chrono::duration<double>(deadline - Clock::now()).count();
      if (left_s <= 0.0) return;
      UdpPeer from;
      const int n = socket_.receive(buffer_.data(), int(buffer_.size()), left_s, &from);
      if (n < 0) throw std::runtime_error("emulator: socket error");
      if (n == 0) return;
      Answer answer;
      const std::string_view bytes(buffer_.data(), std::size_t(n));
      if (!(options_.protocol == ControllerProtocol::kEgm ? read_egm_answer(bytes, &answer)
                                                          : read_answer(bytes, &answer)))
        continue;
      ++got;
      apply(answer);
    }
  }

  EmulatorRun finish() {
    // Cycles without an answer hold the correction the controller had.
    for (std::size_t k = 0; k < run_.correction_rad.size(); ++k) {
      if (!run_.answered[k]) run_.correction_rad[k] = k > 0 ? run_.correction_rad[k - 1] : held_;
    }
    return std::move(run_);
  }

  std::uint64_t ipoc(std::size_t k) const {
    return options_.first_ipoc + std::uint64_t(k) * options_.ipoc_per_cycle;
  }

 private:
  bool read_egm_answer(std::string_view bytes, Answer* out) {
    std::uint32_t seqno = 0;
    if (!codec_.parse_sensor(bytes, &seqno, &out->value_deg)) return false;
    out->ipoc = seqno;
    return true;
  }

  void apply(const Answer& answer) {
    if (answer.ipoc < options_.first_ipoc) return;
    const std::uint64_t offset = answer.ipoc - options_.first_ipoc;
    if (offset % options_.ipoc_per_cycle != 0) return;
    const std::size_t k = std::size_t(offset / options_.ipoc_per_cycle);
    if (k >= run_.answered.size() || run_.answered[k]) return;  // a second answer: discarded
    for (int a = 0; a < kRsiAxes; ++a) {
      const double v = answer.value_deg[std::size_t(a)] / kDegPerRad;
      if (options_.protocol == ControllerProtocol::kEgm) {
        sum_rad_[std::size_t(a)] = v - setpoint_rad_[k][std::size_t(a)];  // target - path
      } else if (options_.mode == RsiCorrectionMode::kIncrement) {
        sum_rad_[std::size_t(a)] += v;
      } else {
        sum_rad_[std::size_t(a)] = v;
      }
    }
    run_.correction_rad[k] = sum_rad_;
    run_.answered[k] = true;
    run_.latency_s[k] = std::chrono::duration<double>(Clock::now() - sent_at_[k]).count();
  }

  UdpSocket& socket_;
  UdpPeer server_;
  const EmulatorOptions& options_;
  const std::vector<std::array<double, kRsiAxes>>& setpoint_rad_;
  EgmCodec codec_;
  EmulatorRun run_;
  std::vector<Clock::time_point> sent_at_;
  std::array<double, kRsiAxes> sum_rad_{};
  std::array<double, kRsiAxes> held_{};
  std::array<char, 2048> buffer_{};
};

}  // namespace

int write_rsi_robot_datagram(std::string_view robot_type, const std::array<double, kRsiAxes>& q_deg,
                             std::uint64_t ipoc, char* buffer, int capacity) {
  const std::string type(robot_type);
  const int n = std::snprintf(
      buffer, std::size_t(capacity),
      "<Rob Type=\"%s\"><RIst X=\"0.0\" Y=\"0.0\" Z=\"0.0\" A=\"0.0\" B=\"0.0\" C=\"0.0\"/>"
      "<AIPos A1=\"%.6f\" A2=\"%.6f\" A3=\"%.6f\" A4=\"%.6f\" A5=\"%.6f\" A6=\"%.6f\"/>"
      "<ASPos A1=\"%.6f\" A2=\"%.6f\" A3=\"%.6f\" A4=\"%.6f\" A5=\"%.6f\" A6=\"%.6f\"/>"
      "<Delay D=\"0\"/><IPOC>%llu</IPOC></Rob>",
      type.c_str(), q_deg[0], q_deg[1], q_deg[2], q_deg[3], q_deg[4], q_deg[5], q_deg[0], q_deg[1],
      q_deg[2], q_deg[3], q_deg[4], q_deg[5], static_cast<unsigned long long>(ipoc));
  return n > 0 && n < capacity ? n : -1;
}

EmulatorRun emulate_controller(UdpSocket& socket, const UdpPeer& server,
                               const std::vector<std::array<double, kRsiAxes>>& setpoint_rad,
                               const EmulatorOptions& options) {
  Emulator emulator(socket, server, options, setpoint_rad);
  const Clock::time_point start = Clock::now();
  for (std::size_t k = 0; k < setpoint_rad.size(); ++k) {
    if (options.paced) {
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(k * options.cycle_s)));
    }
    const auto found = options.faults.find(k);
    InjectedFault fault = found == options.faults.end() ? InjectedFault::kDrop : found->second;
    InjectedFault* injected = found == options.faults.end() ? nullptr : &fault;
    if (injected != nullptr && fault == InjectedFault::kDrop) continue;
    if (injected != nullptr && fault == InjectedFault::kLate) {
      std::this_thread::sleep_for(std::chrono::duration<double>(options.late_delay_s));
    }
    int expected = 1;
    if (injected != nullptr && fault == InjectedFault::kMalformed) emulator.send_malformed(k);
    if (injected != nullptr && fault == InjectedFault::kSwapWithNext &&
        k + 1 < setpoint_rad.size()) {
      emulator.send(k + 1, setpoint_rad[k + 1], nullptr);
      emulator.send(k, setpoint_rad[k], nullptr);
      emulator.collect(2);
      ++k;  // the next cycle's datagram went already
      continue;
    }
    emulator.send(k, setpoint_rad[k], injected);
    if (injected != nullptr && fault == InjectedFault::kDuplicate) {
      emulator.send(k, setpoint_rad[k], nullptr);
      expected = 2;
    }
    emulator.collect(expected);
  }
  EmulatorRun run = emulator.finish();
  for (std::size_t k = 0; k < run.answered.size(); ++k) {
    const auto found = options.faults.find(k);
    const bool dropped = found != options.faults.end() && found->second == InjectedFault::kDrop;
    if (!run.answered[k] && !dropped) ++run.missed;
  }
  return run;
}

}  // namespace imscal::online
