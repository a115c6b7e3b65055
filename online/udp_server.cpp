#include "online/udp_server.hpp"

#include <array>
#include <chrono>

#include "online/rsi_datagram.hpp"

namespace imscal::online {

UdpServerStats serve_udp(UdpSocket& socket, DatagramSession& session, const std::atomic<bool>& stop,
                         const UdpServerOptions& options,
                         const std::function<void()>& after_answer) {
  using Clock = std::chrono::steady_clock;
  std::array<char, kRsiMaxDatagramBytes + 1> in{};
  std::array<char, 1024> out{};
  UdpServerStats stats;
  Clock::time_point last = Clock::now();
  const Clock::time_point origin = last;
  while (!stop.load(std::memory_order_relaxed)) {
    UdpPeer from;
    // One byte more than a datagram may have: a longer one arrives cut and is refused as too long.
    const int n = socket.receive(in.data(), int(in.size()), options.stop_poll_s, &from);
    if (n < 0) break;
    const Clock::time_point now = Clock::now();
    if (n == 0) {
      const double idle_s = std::chrono::duration<double>(now - last).count();
      if (stats.datagrams > 0 && options.idle_timeout_s > 0.0 && idle_s > options.idle_timeout_s)
        break;
      continue;
    }
    last = now;
    ++stats.datagrams;
    const double t_s = std::chrono::duration<double>(now - origin).count();
    const int bytes = session.handle(std::string_view(in.data(), std::size_t(n)), t_s, out.data(),
                                     int(out.size()));
    if (bytes > 0 && socket.send(out.data(), bytes, from)) {
      ++stats.answered;
    } else {
      ++stats.not_answered;
    }
    if (after_answer) after_answer();
  }
  return stats;
}

}  // namespace imscal::online
