// SweepHttpTest — GET /scenes/{id}/sweep over real HTTP (HttpTestFixture.hpp, GL renders): the
// contact sheet decodes with the expected size for N steps of S pixels, its labels are drawn, its
// first and last cells differ where the elbow crease acts and its empty slots are background; the
// JSON steps of the default elbow go from θmin to θmax with t from 0 to 1; a clip sweep's JSON
// equals the activation route's t at the same times; compare parameters apply to the cells.
#include "HttpTestFixture.hpp"

#include <cmath>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class SweepHttpTest : public SharedServerTest {};

/// The cell at (col, row) of a sheet of size×size cells.
Image8 cellOf(const Image8& sheet, int col, int row, int size) {
    Image8 c;
    c.width = c.height = size;
    c.rgba.resize(static_cast<std::size_t>(size) * size * 4);
    for (int y = 0; y < size; ++y)
        std::copy_n(sheet.rgba.begin() +
                        ((static_cast<std::ptrdiff_t>(row) * size + y) * sheet.width + col * size) *
                            4,
                    size * 4, c.rgba.begin() + static_cast<std::ptrdiff_t>(y) * size * 4);
    return c;
}

/// Rows [y0, size) of a cell: below its label.
Image8 belowLabel(const Image8& cell, int y0) {
    Image8 c = cell;
    c.height = cell.height - y0;
    c.rgba.erase(c.rgba.begin(), c.rgba.begin() + static_cast<std::ptrdiff_t>(y0) * cell.width * 4);
    return c;
}

std::string createDefault(const Http& h) {
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    EXPECT_EQ(created.status, 201) << created;
    return "/scenes/" + created.js().value("id", "");
}

TEST_F(SweepHttpTest, JointSweepSheetAndSteps) {
    Http h = http();
    const std::string s = createDefault(h);
    const int size = 96;
    Reply png = h.get(s + "/sweep?placement=elbow_l&steps=5&size=96&msaa=1&yaw=60&pitch=0");
    ASSERT_EQ(png.status, 200) << png;
    EXPECT_EQ(png.header("Content-Type"), "image/png");
    EXPECT_FALSE(png.header("X-Dermis-Backend").empty());
    auto sheet = decodeFrame(png.bytes());
    ASSERT_TRUE(sheet) << sheet.error().message;
    ASSERT_EQ(sheet->width, 3 * size);  // 5 steps: 3 columns
    ASSERT_EQ(sheet->height, 2 * size); // and 2 rows
    const Image8 first = cellOf(*sheet, 0, 0, size), last = cellOf(*sheet, 1, 1, size);
    // Each cell carries its label: white text in its top-left corner.
    for (const Image8* c : {&first, &last}) {
        int white = 0;
        for (int y = 0; y < 18; ++y)
            for (int x = 0; x < 50; ++x) {
                const std::uint8_t* p = &c->rgba[(static_cast<std::size_t>(y) * size + x) * 4];
                white += p[0] == 255 && p[1] == 255 && p[2] == 255;
            }
        EXPECT_GT(white, 30);
    }
    // The elbow bends from 0° to 130°: the character differs below the labels.
    EXPECT_GT(pixelsDiffering(belowLabel(first, 24), belowLabel(last, 24)), 50u);
    // The sixth slot of the 3×2 grid is background.
    const Image8 empty = cellOf(*sheet, 2, 1, size);
    for (std::size_t k = 0; k < empty.rgba.size(); k += 4)
        ASSERT_EQ(empty.rgba[k], 40) << "pixel " << k / 4;

    // The steps as JSON: θ from θmin to θmax, t from 0 to 1 (t is the normalised angle, before the
    // response: linear in θ whatever the response).
    Reply js = h.get(s + "/sweep?placement=elbow_l&steps=5&format=json");
    ASSERT_EQ(js.status, 200) << js;
    const json j = js.js();
    EXPECT_EQ(j["placement"], "elbow_l");
    EXPECT_EQ(j["joint"], "forearm.l");
    EXPECT_EQ(j["axis"], "x");
    EXPECT_EQ(j["theta_min"], 0);
    EXPECT_EQ(j["theta_max"], 130);
    ASSERT_EQ(j["steps"].size(), 5u);
    for (std::size_t k = 0; k < 5; ++k) {
        EXPECT_NEAR(j["steps"][k]["theta"].get<double>(), 130.0 * k / 4.0, 1e-6);
        EXPECT_NEAR(j["steps"][k]["t"].get<double>(), k / 4.0, 1e-4) << j["steps"][k];
        EXPECT_EQ(j["placements"]["elbow_l"][k], j["steps"][k]["t"]);
    }
    EXPECT_GT(j["placements"]["biceps_l"][4].get<double>(), 0.9) << "the biceps follows the elbow";
    ASSERT_EQ(j["placements"]["elbow_r"].size(), 5u);
    EXPECT_EQ(j["placements"]["elbow_r"][0], j["placements"]["elbow_r"][4])
        << "the other arm stays as posed";

    // Compare parameters apply to every cell: with patterns=off the last cell (130°, crease and
    // biceps bulge at full height) differs from the one with patterns.
    Reply off =
        h.get(s + "/sweep?placement=elbow_l&steps=2&size=96&msaa=1&yaw=60&pitch=0&patterns=off");
    Reply on = h.get(s + "/sweep?placement=elbow_l&steps=2&size=96&msaa=1&yaw=60&pitch=0");
    ASSERT_EQ(off.status, 200) << off;
    ASSERT_EQ(on.status, 200) << on;
    auto offSheet = decodeFrame(off.bytes()), onSheet = decodeFrame(on.bytes());
    ASSERT_TRUE(offSheet && onSheet);
    EXPECT_EQ(offSheet->width, 2 * size);
    EXPECT_EQ(offSheet->height, size);
    EXPECT_GT(pixelsDiffering(belowLabel(cellOf(*onSheet, 1, 0, size), 24),
                              belowLabel(cellOf(*offSheet, 1, 0, size), 24)),
              0u)
        << "the crease and bulge at 130° change the frame";
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(SweepHttpTest, ClipSweepMatchesActivation) {
    Http h = http();
    const std::string s = createDefault(h);
    Reply probe = h.get(s + "/sweep?clip=elbow_curl&steps=2&format=json");
    ASSERT_EQ(probe.status, 200) << probe;
    const double duration = probe.js()["duration"];
    ASSERT_GT(duration, 0.0);
    // Steps at multiples of 0.1 s where the duration allows, so that activation samples them.
    const int steps = std::max(2, static_cast<int>(std::lround(duration * 10.0)) + 1);
    Reply sweep = h.get(s + "/sweep?clip=elbow_curl&format=json&steps=" + std::to_string(steps));
    Reply act = h.get(s + "/activation?clip=elbow_curl&fps=10");
    ASSERT_EQ(sweep.status, 200) << sweep;
    ASSERT_EQ(act.status, 200) << act;
    const json sw = sweep.js(), a = act.js();
    EXPECT_EQ(sw["clip"], "elbow_curl");
    EXPECT_TRUE(sw["placement"].is_null());
    ASSERT_EQ(sw["steps"].size(), static_cast<std::size_t>(steps));
    int matched = 0;
    for (const json& step : sw["steps"]) {
        const double time = step["time"];
        for (std::size_t k = 0; k < a["times"].size(); ++k) {
            if (std::abs(a["times"][k].get<double>() - time) > 1e-6) continue;
            ASSERT_EQ(step["t"].size(), a["placements"].size());
            for (const auto& [pid, ts] : a["placements"].items())
                EXPECT_NEAR(step["t"][pid].get<double>(), ts[k].get<double>(), 1e-6)
                    << pid << " at " << time;
            ++matched;
        }
    }
    EXPECT_GE(matched, 2) << "the first and the last time match at least";
    EXPECT_EQ(sw["steps"].back()["time"], a["times"].back());

    // With a placement, each step's t names only it; the sheet renders with the clip.
    Reply one = h.get(s + "/sweep?clip=elbow_curl&placement=elbow_l&steps=3&format=json");
    ASSERT_EQ(one.status, 200) << one;
    const json oneDoc = one.js();
    EXPECT_EQ(oneDoc["placement"], "elbow_l");
    for (const json& step : oneDoc["steps"])
        EXPECT_EQ(step["t"].size(), 1u) << step;
    Reply png = h.get(s + "/sweep?clip=elbow_curl&steps=4&size=48&msaa=1");
    ASSERT_EQ(png.status, 200) << png;
    auto sheet = decodeFrame(png.bytes());
    ASSERT_TRUE(sheet);
    EXPECT_EQ(sheet->width, 96);
    EXPECT_EQ(sheet->height, 96);
    ASSERT_EQ(h.del(s).status, 204);
}

} // namespace
