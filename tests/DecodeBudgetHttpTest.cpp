// DecodeBudgetHttpTest — the memory of image decodes (issue #27, item 2):
//   * DecodeBudget alone: reservations that fit are granted, one that does not waits for a
//     release, and is refused (Unavailable) when none comes in time; a request over the budget
//     runs alone; eight threads never hold more than the budget;
//   * a server (in this process, --max-image-side 4096): eight parallel uploads of a 128 KB TIFF
//     declaring 8192² are each answered 413 from the decoder's spec, before any pixel (before: each
//     decoded ~450 MB first, 4.1 GB for eight), and this process's resident memory grows by less
//     than 64 MB; a real 256² TIFF is still accepted.
#include "HttpTestFixture.hpp"
#include "ProcessStats.hpp"
#include "service/decode_budget.hpp"

#include <future>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// A little-endian baseline TIFF declaring w × h 8-bit grey pixels, uncompressed, with `data`
/// bytes of pixel data (fewer than declared: the file is cut short).
std::string tiff(std::uint32_t w, std::uint32_t h, std::size_t data) {
    std::string t("II\x2a\0\x08\0\0\0", 8);
    auto u16 = [&](std::uint16_t v) { t += char(v & 0xff), t += char(v >> 8); };
    auto u32 = [&](std::uint32_t v) { for (int k = 0; k < 4; ++k) t += char((v >> (8 * k)) & 0xff); };
    const std::uint16_t n = 9;
    const std::uint32_t dataAt = 8 + 2 + n * 12 + 4;
    u16(n);
    auto entry = [&](std::uint16_t tag, std::uint16_t type, std::uint32_t value) {
        u16(tag), u16(type), u32(1);
        if (type == 3) u16(static_cast<std::uint16_t>(value)), u16(0);
        else u32(value);
    };
    entry(256, 4, w);                 // ImageWidth
    entry(257, 4, h);                 // ImageLength
    entry(258, 3, 8);                 // BitsPerSample
    entry(259, 3, 1);                 // Compression: none
    entry(262, 3, 1);                 // Photometric: black is zero
    entry(273, 4, dataAt);            // StripOffsets
    entry(277, 3, 1);                 // SamplesPerPixel
    entry(278, 4, h);                 // RowsPerStrip
    entry(279, 4, w * h);             // StripByteCounts (as declared)
    u32(0);                           // no next IFD
    t.append(data, char(128));
    return t;
}

} // namespace

TEST(DecodeBudgetTest, ReservesWaitsAndRefuses) {
    DecodeBudget budget(100);
    auto a = budget.reserve(60, std::chrono::milliseconds(0), "x");
    ASSERT_TRUE(a);
    auto refused = budget.reserve(60, std::chrono::milliseconds(50), "body");
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::Unavailable);
    EXPECT_EQ(refused.error().field, "body");
    EXPECT_EQ(budget.refused(), 1u);
    // A waiting reservation gets the room a release makes.
    auto waiter = std::async(std::launch::async, [&] { return bool(budget.reserve(60, std::chrono::seconds(5), "x")); });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    { auto gone = std::move(*a); } // released here
    EXPECT_TRUE(waiter.get());
    EXPECT_EQ(budget.inUse(), 0u) << "the waiter's lease ended with its lambda";
    auto huge = budget.reserve(1000, std::chrono::milliseconds(0), "x");
    ASSERT_TRUE(huge) << "over the budget: runs alone";
    EXPECT_EQ(huge->bytes(), 100u);
    // Eight threads, each holding 30 for a moment: never more than the budget at once.
    DecodeBudget shared(100);
    std::vector<std::thread> threads;
    std::atomic<int> granted{0};
    for (int k = 0; k < 8; ++k)
        threads.emplace_back([&] {
            for (int i = 0; i < 20; ++i)
                if (auto l = shared.reserve(30, std::chrono::seconds(5), "x")) {
                    ++granted;
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
                }
        });
    for (auto& t : threads) t.join();
    EXPECT_EQ(granted.load(), 160);
    EXPECT_LE(shared.peak(), 100u);
    EXPECT_EQ(shared.inUse(), 0u);
}

class DecodeBudgetHttpTest : public SharedServerTest {};

TEST_F(DecodeBudgetHttpTest, HostileTiffsAreRefusedFromTheirSpecBeforeAnyPixel) {
    // A real TIFF within the limits is decoded as before (and loads the OpenImageIO module, whose
    // libraries are not what is measured below).
    const std::string ok = tiff(256, 256, 256 * 256);
    Reply r = http().upload("/patterns?name=tiff256", std::vector<std::uint8_t>(ok.begin(), ok.end()), "image/tiff");
    EXPECT_EQ(r.status, 201) << r;
    const std::string hostile = tiff(8192, 8192, 128 * 1024);
    const long before = residentKb();
    std::vector<std::future<Reply>> uploads;
    for (int k = 0; k < 8; ++k)
        uploads.push_back(std::async(std::launch::async, [&, k] {
            // Each upload differs by a byte past the pixels, so none is a known content address.
            std::string bytes = hostile + char(k);
            return http().upload("/patterns?name=hostile" + std::to_string(k),
                                 std::vector<std::uint8_t>(bytes.begin(), bytes.end()), "image/tiff");
        }));
    for (auto& u : uploads) {
        Reply r = u.get();
        expectError(r, 413, "body");
        EXPECT_NE(r.js()["error"]["message"].get<std::string>().find("8192x8192"), std::string::npos) << r;
    }
    const long grown = residentKb() - before;
    std::cout << "[ figures ] eight 8192² TIFF uploads: resident memory +" << grown / 1024 << " MB\n";
    EXPECT_LT(grown, 64 * 1024) << "no decode of 8192² pixels (one would be 256 MB of floats)";
}
