#pragma once
// A UDP socket (POSIX, IPv4) for the controller interfaces: bound once, then datagrams received
// with a timeout and answered to their sender, without allocating.
#include <netinet/in.h>

#include <cstdint>
#include <string>

namespace imscal::online {

// The address of a datagram's sender, or of the peer a datagram goes to.
struct UdpPeer {
  sockaddr_in address{};
};

class UdpSocket {
 public:
  // Binds to host:port (IPv4 dotted address; port 0: a free port the system picks). Throws
  // std::runtime_error with the system's reason.
  UdpSocket(const std::string& host, std::uint16_t port);
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  std::uint16_t port() const { return port_; }

  // Waits up to timeout_s (< 0: forever) for a datagram: its length (a longer one is cut to
  // `capacity`), 0 when none came, -1 on a socket error.
  int receive(char* buffer, int capacity, double timeout_s, UdpPeer* from) noexcept;
  bool send(const char* data, int bytes, const UdpPeer& to) noexcept;

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

// The peer host:port (IPv4 dotted address); throws std::invalid_argument for a bad address.
UdpPeer udp_peer(const std::string& host, std::uint16_t port);

}  // namespace imscal::online
