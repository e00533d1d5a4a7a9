// dermis-coldbench — how long the server executable's commands take as a user runs them: each
// command is a fresh child process (fork + exec, output to /dev/null), timed from fork to exit,
// median of --repeat runs (default 5) after one unmeasured warm-up run (which fills Mesa's
// on-disk shader cache, as any earlier use on the machine would). Also prints the children's CPU
// time (user + system), which does not depend on what else the machine is running, and one
// render with an empty Mesa shader cache (a first use on a new machine).
//
//   dermis-coldbench [--repeat N] [--server PATH] [--gl B]    → JSON on stdout: {"cold": {...}}
//
// Fails (exit 1, message on stderr) when a command exits non-zero.
#include "BuildPaths.hpp"
#include <nlohmann/json.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace {

struct Run {
    double wallMs = 0, cpuMs = 0;
};

double tvMs(const timeval& tv) {
    return static_cast<double>(tv.tv_sec) * 1e3 + static_cast<double>(tv.tv_usec) / 1e3;
}

/// Runs argv with extra environment assignments; exits the benchmark on failure.
Run runOnce(const std::vector<std::string>& argv, const std::vector<std::string>& env) {
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid < 0) {
        std::perror("dermis-coldbench: fork");
        std::exit(1);
    }
    if (pid == 0) {
        for (const std::string& e : env)
            putenv(const_cast<char*>(e.c_str()));
        const int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 1);
        std::vector<char*> args;
        for (const std::string& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execv(args[0], args.data());
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    const auto t1 = std::chrono::steady_clock::now();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::cerr << "dermis-coldbench: command failed:";
        for (const std::string& a : argv)
            std::cerr << " " << a;
        std::cerr << "\n";
        std::exit(1);
    }
    return {std::chrono::duration<double, std::milli>(t1 - t0).count(),
            tvMs(usage.ru_utime) + tvMs(usage.ru_stime)};
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double round1(double v) { return std::round(v * 10.0) / 10.0; }

nlohmann::json measure(const std::vector<std::string>& argv, int repeat, double goalMs,
                       const std::vector<std::string>& env = {}) {
    runOnce(argv, env); // warm-up: page cache, Mesa's shader cache
    std::vector<double> wall, cpu;
    for (int k = 0; k < repeat; ++k) {
        const Run r = runOnce(argv, env);
        wall.push_back(r.wallMs);
        cpu.push_back(r.cpuMs);
    }
    std::string command;
    for (std::size_t k = 1; k < argv.size(); ++k)
        command += (k > 1 ? " " : "") + argv[k];
    return {{"command", command},
            {"median_ms", round1(median(wall))},
            {"min_ms", round1(*std::min_element(wall.begin(), wall.end()))},
            {"cpu_median_ms", round1(median(cpu))},
            {"goal_ms", goalMs},
            {"runs", repeat}};
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 5;
    std::string server = dermis::build::serverExe(), gl = "egl-surfaceless";
    for (int k = 1; k < argc; ++k) {
        const std::string a = argv[k];
        if (a == "--repeat" && k + 1 < argc) repeat = std::max(1, std::atoi(argv[++k]));
        else if (a == "--server" && k + 1 < argc) server = argv[++k];
        else if (a == "--gl" && k + 1 < argc) gl = argv[++k];
        else {
            std::cerr << "usage: dermis-coldbench [--repeat N] [--server PATH] [--gl B]\n";
            return 2;
        }
    }
    const std::string source = dermis::build::sourceDir();
    const std::filesystem::path out =
        std::filesystem::temp_directory_path() / ("dermis-coldbench-" + std::to_string(getpid()));
    std::filesystem::create_directories(out);
    const std::string cesium = source + "/examples/cesiumman.scene.json";
    const std::string dflt = source + "/models/default.scene.json";
    const std::vector<std::string> oneShot = {server, "render", "--scene", cesium, "--out",
                                              (out / "one.png").string(), "--size", "1024x1024",
                                              "--gl", gl};
    nlohmann::json cold;
    cold["help"] = measure({server, "--help"}, repeat, 20);
    cold["info"] = measure({server, "info", "--gl", gl}, repeat, 100);
    cold["render_one_1024"] = measure(oneShot, repeat, 150);
    // A first use on a new machine: Mesa's shader cache empty (a fresh folder every run).
    {
        std::vector<double> wall, cpu;
        for (int k = 0; k < repeat; ++k) {
            const std::filesystem::path cache = out / ("mesa-cache-" + std::to_string(k));
            const Run r = runOnce(oneShot, {"MESA_SHADER_CACHE_DIR=" + cache.string()});
            wall.push_back(r.wallMs);
            cpu.push_back(r.cpuMs);
        }
        cold["render_one_1024_empty_shader_cache"] = {{"median_ms", round1(median(wall))},
                                                      {"cpu_median_ms", round1(median(cpu))},
                                                      {"runs", repeat}};
    }
    const std::vector<std::string> frames = {server, "render", "--scene", dflt, "--out",
                                             (out / "f_%04d.png").string(), "--frames",
                                             "0:1.18:0.02", "--size", "1024x1024", "--gl", gl};
    // The scene's own anti-aliasing (render.aa auto: post on llvmpipe, MSAA 4x on a GPU), then
    // MSAA 4x and none by option, and the default with JPEG frames.
    auto with = [&](std::vector<std::string> extra, const char* pattern = "f_%04d.png") {
        std::vector<std::string> cmd = frames;
        cmd[5] = (out / pattern).string();
        cmd.insert(cmd.end(), extra.begin(), extra.end());
        return cmd;
    };
    cold["frames60_1024_default_aa"] = measure(frames, repeat, 1500);
    cold["frames60_1024_default_aa_jpeg"] = measure(with({}, "f_%04d.jpg"), repeat, 1500);
    cold["frames60_1024_msaa4"] = measure(with({"--aa", "msaa", "--msaa", "4"}), repeat, 1500);
    cold["frames60_1024_msaa1"] = measure(with({"--msaa", "1"}), repeat, 1500);
    for (const char* key : {"frames60_1024_default_aa", "frames60_1024_default_aa_jpeg", "frames60_1024_msaa4",
                            "frames60_1024_msaa1"})
        cold[key]["ms_per_frame"] = round1(cold[key]["median_ms"].get<double>() / 60.0);
    std::error_code ec;
    std::filesystem::remove_all(out, ec);
    std::cout << nlohmann::json{{"cold", cold}}.dump(2) << "\n";
    return 0;
}
