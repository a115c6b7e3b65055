#include "online/udp_socket.hpp"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace imscal::online {

UdpPeer udp_peer(const std::string& host, std::uint16_t port) {
  UdpPeer peer;
  peer.address.sin_family = AF_INET;
  peer.address.sin_port = htons(port);
  if (inet_pton(AF_INET, host.c_str(), &peer.address.sin_addr) != 1)
    throw std::invalid_argument("not an IPv4 address: '" + host + "'");
  return peer;
}

UdpSocket::UdpSocket(const std::string& host, std::uint16_t port) {
  const UdpPeer local = udp_peer(host, port);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("UDP socket: ") + std::strerror(errno));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&local.address), sizeof local.address) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("cannot bind UDP " + host + ":" + std::to_string(port) + ": " +
                             reason);
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &length);
  port_ = ntohs(bound.sin_port);
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

int UdpSocket::receive(char* buffer, int capacity, double timeout_s, UdpPeer* from) noexcept {
  pollfd p{fd_, POLLIN, 0};
  const int timeout_ms = timeout_s < 0.0 ? -1 : static_cast<int>(std::ceil(timeout_s * 1e3));
  for (;;) {
    const int ready = ::poll(&p, 1, timeout_ms);
    if (ready == 0) return 0;
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return -1;
    break;
  }
  socklen_t length = sizeof from->address;
  const ssize_t n = ::recvfrom(fd_, buffer, std::size_t(capacity), 0,
                               reinterpret_cast<sockaddr*>(&from->address), &length);
  return n < 0 ? -1 : static_cast<int>(n);
}

bool UdpSocket::send(const char* data, int bytes, const UdpPeer& to) noexcept {
  const ssize_t n = ::sendto(fd_, data, std::size_t(bytes), 0,
                             reinterpret_cast<const sockaddr*>(&to.address), sizeof to.address);
  return n == bytes;
}

}  // namespace imscal::online
