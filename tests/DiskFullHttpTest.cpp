// DiskFullHttpTest — a data folder that fills up (issue #27, item 7): a server whose data folder
// is a 384 KB tmpfs takes scene edits until the disk is full; then every edit is answered a JSON
// 5xx `io_error` whose message and field name the data folder only as "<data>" (before: the
// absolute path), the scene stays at its last acknowledged revision (nothing half written), and
// reads go on. Mounting a tmpfs needs CAP_SYS_ADMIN (CI and `make test` run as root here); without
// it the test fails and says so rather than skipping.
#include "HttpTestFixture.hpp"

#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// A tmpfs of `kb` KB mounted on a fresh folder, unmounted on destruction.
class SmallDisk {
public:
    explicit SmallDisk(int kb) : path_(dir_ / "disk") {
        std::filesystem::create_directories(path_);
        const std::string opts = "size=" + std::to_string(kb) + "k";
        if (::mount("tmpfs", path_.c_str(), "tmpfs", 0, opts.c_str()) != 0)
            error_ = std::string("mount -t tmpfs: ") + std::strerror(errno) + " (the test needs CAP_SYS_ADMIN)";
        else mounted_ = true;
    }
    ~SmallDisk() {
        if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
    }
    const std::string& path() const { return path_; }
    const std::string& error() const { return error_; }
    bool mounted() const { return mounted_; }

private:
    TempDir dir_;
    std::string path_, error_;
    bool mounted_ = false;
};

} // namespace

TEST(DiskFullHttpTest, EditsOnAFullDiskAreJson5xxThatNameNoServerPath) {
    SmallDisk disk(384);
    ASSERT_TRUE(disk.mounted()) << disk.error();
    const std::string data = disk.path() + "/data";
    {
        auto svc = Service::open(data, testBackend(), mainLimits());
        ASSERT_TRUE(svc) << svc.error().message;
        ApiOptions opt;
        opt.bind = "127.0.0.1";
        opt.port = 0;
        Api api(**svc, opt);
        auto port = api.bind();
        ASSERT_TRUE(port) << port.error().message;
        std::thread serving([&] { api.run(); });
        Http http(*port);
        for (int i = 0; i < 500 && http.get("/health").status != 200; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));

        // A scene of 24 placements (the test limit) with long labels, ~10 KB; each edit changes a
        // label, so that its revision — a patch in the history — takes a few hundred bytes.
        json doc = smallScene();
        doc["placements"] = json::array();
        for (int k = 0; k < 24; ++k) {
            json p = placementOf("crease", "p" + std::to_string(k));
            p["label"] = std::string(120, char('a' + k % 26));
            doc["placements"].push_back(p);
        }
        Reply created = http.post("/scenes", doc);
        ASSERT_EQ(created.status, 201) << created;
        const std::string id = created.js()["id"];
        std::uint64_t acknowledged = created.js()["revision"];
        Reply refused;
        for (int i = 0; i < 5000; ++i) {
            Reply r = http.patch("/scenes/" + id + "/placements/p" + std::to_string(i % 24),
                                 {{"h", 1.0 + 0.001 * (i + 1)},
                                  {"label", std::to_string(i) + std::string(110, char('a' + i % 26))}});
            if (r.status != 200) {
                refused = r;
                break;
            }
            acknowledged = r.js()["revision"];
        }
        ASSERT_GE(refused.status, 500) << "the 384 KB disk never filled: " << refused;
        expectError(refused, refused.status);
        const json e = refused.js()["error"];
        EXPECT_EQ(e["code"], "io_error") << refused;
        const std::string text = e["message"].get<std::string>() + " " + e["field"].get<std::string>();
        EXPECT_EQ(text.find(disk.path()), std::string::npos) << "names the data folder: " << text;
        EXPECT_EQ(text.find("/tmp"), std::string::npos) << text;
        std::cout << "[ figures ] disk full after revision " << acknowledged << ": " << refused.status << " "
                  << refused.body << "\n";
        // Nothing half written: the scene reads at its last acknowledged revision; reads go on.
        Reply now = http.get("/scenes/" + id);
        ASSERT_EQ(now.status, 200) << now;
        EXPECT_EQ(now.js()["revision"], acknowledged);
        EXPECT_EQ(http.get("/scenes").status, 200);
        api.stop();
        serving.join();
    }
}
