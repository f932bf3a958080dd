#include "udp_socket.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "sketchnav/core/error.h"

namespace sketchnav::drivers::net {

std::string Endpoint::host() const {
  char buf[INET_ADDRSTRLEN] = {0};
  ::inet_ntop(AF_INET, &addr.sin_addr, buf, sizeof buf);
  return buf;
}
int Endpoint::port() const {
  return ntohs(addr.sin_port);
}
bool Endpoint::isLoopback() const {
  return (ntohl(addr.sin_addr.s_addr) >> 24) == 127;
}

Endpoint Endpoint::resolve(const std::string& host, int port, const std::string& what) {
  if (port < 0 || port > 65535)
    throw InputError(what + ": port " + std::to_string(port) + " out of range 0..65535");
  Endpoint e;
  e.addr.sin_family = AF_INET;
  e.addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, host.c_str(), &e.addr.sin_addr) == 1) return e;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* res = nullptr;
  if (::getaddrinfo(host.c_str(), nullptr, &hints, &res) != 0 || res == nullptr)
    throw InputError(what + ": cannot resolve host '" + host + "'");
  e.addr.sin_addr = reinterpret_cast<sockaddr_in*>(res->ai_addr)->sin_addr;
  ::freeaddrinfo(res);
  return e;
}

UdpSocket::UdpSocket() {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw RuntimeError(std::string("cannot create a UDP socket: ") + strerror(errno));
}
UdpSocket::~UdpSocket() {
  close();
}

void UdpSocket::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void UdpSocket::bind(const Endpoint& local) {
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&local.addr), sizeof local.addr) != 0)
    throw RuntimeError("cannot bind UDP " + local.str() + ": " + strerror(errno));
}

Endpoint UdpSocket::local() const {
  Endpoint e;
  socklen_t len = sizeof e.addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&e.addr), &len);
  return e;
}

bool UdpSocket::sendTo(const std::vector<std::uint8_t>& data, const Endpoint& to) {
  if (fd_ < 0) return false;
  const ssize_t n = ::sendto(fd_, data.data(), data.size(), MSG_NOSIGNAL,
                             reinterpret_cast<const sockaddr*>(&to.addr), sizeof to.addr);
  return n == static_cast<ssize_t>(data.size());
}

long UdpSocket::recvFrom(std::vector<std::uint8_t>& buf, Endpoint& from, double timeout_s) {
  if (fd_ < 0) return -1;
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>(std::ceil(std::max(0.0, timeout_s) * 1000.0));
  const int r = ::poll(&p, 1, ms);
  if (r == 0) return 0;
  if (r < 0) return errno == EINTR ? 0 : -1;
  buf.resize(65536);
  socklen_t len = sizeof from.addr;
  const ssize_t n = ::recvfrom(fd_, buf.data(), buf.size(), MSG_TRUNC,
                               reinterpret_cast<sockaddr*>(&from.addr), &len);
  if (n < 0) return (errno == EAGAIN || errno == EINTR || errno == ECONNREFUSED) ? 0 : -1;
  // A zero-length datagram is legal UDP; report it as one byte of garbage-sized payload so
  // callers count it instead of mistaking it for a timeout.
  buf.resize(std::min<std::size_t>(static_cast<std::size_t>(n), buf.size()));
  return n == 0 ? 1 : static_cast<long>(n);
}

}  // namespace sketchnav::drivers::net
