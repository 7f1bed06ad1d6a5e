#include "server/service/listen_address.h"

#include <arpa/inet.h>

namespace mbopt::service {

namespace {

bool IsUnixSocketAddress(const std::string& address) {
  return address.rfind("unix:", 0) == 0 || address.rfind("unix-abstract:", 0) == 0;
}

}  // namespace

bool IsLoopbackAddress(const std::string& listen_address) {
  if (IsUnixSocketAddress(listen_address)) return true;
  std::string host;
  if (!listen_address.empty() && listen_address.front() == '[') {
    const std::size_t close = listen_address.find(']');
    if (close == std::string::npos) return false;
    host = listen_address.substr(1, close - 1);
  } else {
    const std::size_t colon = listen_address.rfind(':');
    host = colon == std::string::npos ? listen_address : listen_address.substr(0, colon);
  }
  if (host == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, host.c_str(), &v6) == 1) return IN6_IS_ADDR_LOOPBACK(&v6);
  return false;
}

std::string DialAddress(const std::string& listen_address, int port) {
  if (IsUnixSocketAddress(listen_address)) return listen_address;
  const std::size_t colon = listen_address.rfind(':');
  return (colon == std::string::npos ? listen_address : listen_address.substr(0, colon)) + ":" + std::to_string(port);
}

}  // namespace mbopt::service
