#include "online/datagram_session.hpp"

namespace imscal::online {

const char* to_string(SessionFault fault) {
  switch (fault) {
    case SessionFault::kMalformed:
      return "malformed datagram";
    case SessionFault::kLate:
      return "late datagram";
    case SessionFault::kLost:
      return "lost datagrams";
    case SessionFault::kDuplicated:
      return "duplicated counter";
    case SessionFault::kReordered:
      return "reordered counter";
    case SessionFault::kUnknownRobot:
      return "unknown robot";
    case SessionFault::kOffPath:
      return "set-point off the loaded path";
    case SessionFault::kBadFeedback:
      return "measured joints not finite or off the commanded ones";
    case SessionFault::kMotorsOff:
      return "motors off";
    case SessionFault::kNotAtStart:
      return "robot not at the path's first pose";
  }
  return "?";
}

void DatagramSession::record(std::uint64_t counter, SessionFault fault, int detail,
                             double value) noexcept {
  if (fault_count_ == kSessionFaultCapacity) {
    fault_head_ = (fault_head_ + 1) % kSessionFaultCapacity;
    --fault_count_;
  }
  faults_[std::size_t((fault_head_ + fault_count_) % kSessionFaultCapacity)] =
      SessionFaultEvent{counter, fault, detail, value};
  ++fault_count_;
}

int DatagramSession::read_faults(SessionFaultEvent* out, int capacity) noexcept {
  int n = 0;
  for (; n < capacity && fault_count_ > 0; ++n, --fault_count_) {
    out[n] = faults_[std::size_t(fault_head_)];
    fault_head_ = (fault_head_ + 1) % kSessionFaultCapacity;
  }
  return n;
}

}  // namespace imscal::online
