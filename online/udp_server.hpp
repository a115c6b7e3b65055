#pragma once
// The server loop of the controller interfaces: every datagram received on the socket goes to
// the session (online/rsi_session.hpp, online/egm_session.hpp) and its answer straight back to
// the sender, then the caller's hook
// runs (logging the faults and events, outside the time between receive and send).
#include <atomic>
#include <cstdint>
#include <functional>

#include "online/datagram_session.hpp"
#include "online/udp_socket.hpp"

namespace imscal::online {

struct UdpServerStats {
  std::uint64_t datagrams = 0;
  std::uint64_t answered = 0;
  std::uint64_t not_answered = 0;  // malformed, or the answer could not be sent
};

struct UdpServerOptions {
  // > 0: return when no datagram came for this long after the first one [s].
  double idle_timeout_s = 0.0;
  double stop_poll_s = 0.1;  // how often `stop` is looked at while no datagram comes
};

// Runs until `stop` is set, the idle timeout passes or the socket fails.
UdpServerStats serve_udp(UdpSocket& socket, DatagramSession& session, const std::atomic<bool>& stop,
                         const UdpServerOptions& options,
                         const std::function<void()>& after_answer = {});

}  // namespace imscal::online
