// Test helper: resident memory of a process (VmRSS from /proc/<pid>/status), for the suites that
// check memory growth (ServerProcessHttpTest, SlowClientHttpTest, GpuCacheHttpTest). Linux only.
#pragma once

#include <sys/types.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace dermis::test {

/// Resident memory in kB of process `pid` (0: this process); −1 when unknown.
inline long residentKb(pid_t pid = 0) {
    std::ifstream in(pid == 0 ? std::string("/proc/self/status")
                              : "/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
    return -1;
}

} // namespace dermis::test
