// Test helper: a raw TCP connection to a server on 127.0.0.1, for the suites that speak HTTP byte
// by byte (SmugglingHttpTest, FairShareHttpTest). Linux: every address of 127/8 is on lo, so a
// client can appear as another peer by binding its source address first.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>

namespace dermis::test {

/// A connected socket to 127.0.0.1:`port` from source address `from` (dotted IPv4 of 127/8);
/// -1 when binding or connecting fails. The caller closes it.
inline int connectLoopback(int port, const char* from = "127.0.0.1") {
    const int s = ::socket(AF_INET, SOCK_STREAM, 0);
    if (s < 0) return -1;
    sockaddr_in src{};
    src.sin_family = AF_INET;
    ::inet_pton(AF_INET, from, &src.sin_addr);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(s, reinterpret_cast<sockaddr*>(&src), sizeof src) != 0 ||
        ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        ::close(s);
        return -1;
    }
    return s;
}

} // namespace dermis::test
