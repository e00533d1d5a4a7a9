// SweepTest — the pure parts of SPEC §6 Sweep: the 5×7 label font (glyph pixels, widths, scale,
// clipping, unknown code points), contact-sheet layout and composition, cell labels, and the
// steps of joint and clip sweeps on the default scene (θ from θmin to θmax, t from 0 to 1, the
// other joints as posed, clip sweeps equal to clipActivation, planFrame giving the same t).
// No GL, no HTTP.
#include "core/sweep.hpp"
#include "core/activation.hpp"
#include "core/bitmap_font.hpp"
#include "core/contact_sheet.hpp"
#include "core/frame_plan.hpp"
#include "io/scene_files.hpp"

#include "DefaultSceneFixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {


Image8 blank(int w, int h, std::uint8_t grey = 0) {
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.assign(static_cast<std::size_t>(w) * h * 4, grey);
    for (std::size_t k = 3; k < img.rgba.size(); k += 4)
        img.rgba[k] = 255;
    return img;
}

bool lit(const Image8& img, int x, int y) {
    return img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4] > 128;
}

/// The glyph art of `rows` ('#' set) as it should appear at (x0, y0) with `scale`.
void expectGlyph(const Image8& img, int x0, int y0, int scale,
                 const std::vector<std::string>& rows) {
    for (int y = 0; y < kGlyphHeight * scale; ++y)
        for (int x = 0; x < kGlyphWidth * scale; ++x)
            EXPECT_EQ(
                lit(img, x0 + x, y0 + y),
                rows[static_cast<std::size_t>(y / scale)][static_cast<std::size_t>(x / scale)] ==
                    '#')
                << "pixel (" << x << ", " << y << ") at scale " << scale;
}

int litCount(const Image8& img) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            n += lit(img, x, y);
    return n;
}

const Rgba kWhite{255, 255, 255, 255};

TEST(SweepTest, FontDrawsItsGlyphsPixelForPixel) {
    Image8 img = blank(40, 20);
    const int end = drawText(img, 2, 3, "7\u03b8", 1, kWhite);
    EXPECT_EQ(end, 2 + 2 * kGlyphAdvance);
    expectGlyph(img, 2, 3, 1, {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."});
    expectGlyph(img, 2 + kGlyphAdvance, 3, 1,
                {".###.", "#...#", "#...#", "#####", "#...#", "#...#", ".###."});
    // Nothing outside the two glyph boxes.
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (y < 3 || y >= 10 || x < 2 || x >= 13 || x == 7)
                EXPECT_FALSE(lit(img, x, y)) << x << "," << y;

    Image8 big = blank(20, 20);
    drawText(big, 1, 1, "t", 2, kWhite);
    expectGlyph(big, 1, 1, 2, {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."});
    EXPECT_EQ(litCount(big), 4 * 11);

    EXPECT_EQ(textWidth("", 1), 0);
    EXPECT_EQ(textWidth("t=0.50", 1), 6 * kGlyphAdvance - 1);
    EXPECT_EQ(textWidth("\u03b8=45\u00b0", 2), 2 * (5 * kGlyphAdvance - 1)); // θ and ° are one each
}

TEST(SweepTest, FontMapsCaseAndDrawsUnknownsAsQuestionMarks) {
    ASSERT_NE(glyphRows(U'A'), nullptr);
    EXPECT_EQ(glyphRows(U'A'), glyphRows(U'a'));
    EXPECT_EQ(glyphRows(U'#'), nullptr);
    EXPECT_EQ(glyphRows(U'\u00e9'), nullptr);
    for (char32_t c :
         std::u32string(U"0123456789abcdefghijklmnopqrstuvwxyz.,-+=_:/()? \u00b0\u03b8"))
        EXPECT_NE(glyphRows(c), nullptr) << static_cast<int>(c);
    // Every glyph but the space is distinct and non-empty.
    const std::u32string all = U"0123456789abcdefghijklmnopqrstuvwxyz.,-+=_:/()?\u00b0\u03b8";
    for (std::size_t i = 0; i < all.size(); ++i) {
        int bits = 0;
        for (auto r : *glyphRows(all[i]))
            bits += __builtin_popcount(r);
        EXPECT_GT(bits, 0);
        for (std::size_t j = i + 1; j < all.size(); ++j)
            EXPECT_NE(*glyphRows(all[i]), *glyphRows(all[j]));
    }
    Image8 a = blank(10, 10), b = blank(10, 10), c = blank(10, 10);
    drawText(a, 0, 0, "#", 1, kWhite);
    drawText(b, 0, 0, "?", 1, kWhite);
    drawText(c, 0, 0, "\xff", 1, kWhite); // a malformed byte
    EXPECT_EQ(a.rgba, b.rgba);
    EXPECT_EQ(c.rgba, b.rgba);
}

TEST(SweepTest, FontClipsAtTheEdges) {
    Image8 img = blank(8, 8);
    drawText(img, -3, -2, "88", 3, kWhite); // mostly outside: no write out of bounds
    EXPECT_GT(litCount(img), 0);
    Image8 none = blank(8, 8);
    drawText(none, 100, 100, "8", 1, kWhite);
    drawText(none, -100, 0, "8", 1, kWhite);
    EXPECT_EQ(litCount(none), 0);
    shadeRect(none, -5, -5, 100, 100, 0.5); // clipped too
}

TEST(SweepTest, SheetLayoutIsRoughlySquare) {
    const std::pair<std::size_t, std::pair<int, int>> cases[] = {
        {1, {1, 1}}, {2, {2, 1}},  {3, {2, 2}},  {4, {2, 2}},  {5, {3, 2}}, {8, {3, 3}},
        {9, {3, 3}}, {10, {4, 3}}, {16, {4, 4}}, {17, {5, 4}}, {64, {8, 8}}};
    for (auto [n, cr] : cases) {
        const SheetLayout l = sheetLayout(n);
        EXPECT_EQ(l.cols, cr.first) << n;
        EXPECT_EQ(l.rows, cr.second) << n;
    }
    EXPECT_EQ(sheetLayout(0).cols, 0);
}

TEST(SweepTest, SheetPutsEachCellInItsSlot) {
    std::vector<Image8> cells;
    for (int k = 0; k < 5; ++k) {
        Image8 c = blank(6, 4, static_cast<std::uint8_t>(10 * (k + 1)));
        c.rgba[1] = static_cast<std::uint8_t>(k); // first pixel's green marks the cell
        cells.push_back(c);
    }
    auto sheet = composeSheet(cells, sheetLayout(cells.size()), {1, 2, 3, 255});
    ASSERT_TRUE(sheet) << sheet.error().message;
    ASSERT_EQ(sheet->width, 3 * 6);
    ASSERT_EQ(sheet->height, 2 * 4);
    auto px = [&](int x, int y, int c) {
        return sheet->rgba[(static_cast<std::size_t>(y) * sheet->width + x) * 4 + c];
    };
    for (int k = 0; k < 5; ++k) {
        const int x0 = (k % 3) * 6, y0 = (k / 3) * 4;
        EXPECT_EQ(px(x0, y0, 1), k);
        EXPECT_EQ(px(x0 + 5, y0 + 3, 0), 10 * (k + 1));
        EXPECT_EQ(px(x0 + 5, y0 + 3, 3), 255);
    }
    EXPECT_EQ(px(12, 4, 0), 1); // the sixth slot is background
    EXPECT_EQ(px(17, 7, 2), 3);

    cells[3] = blank(6, 5);
    EXPECT_FALSE(composeSheet(cells, sheetLayout(cells.size())));
    EXPECT_FALSE(composeSheet({}, {1, 1}));
    EXPECT_FALSE(composeSheet({blank(2, 2), blank(2, 2)}, {1, 1}));
}

TEST(SweepTest, LabelsFitTheCell) {
    Image8 cell = blank(64, 64, 200);
    labelCell(cell, {"\u03b8=45.0\u00b0", "t=0.35"});
    // The box is darkened, the text white, below it the cell untouched.
    EXPECT_EQ(labelScale(cell), 1);
    int white = 0;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 60; ++x)
            white += cell.rgba[(static_cast<std::size_t>(y) * 64 + x) * 4] == 255;
    EXPECT_GT(white, 20);
    EXPECT_EQ(cell.rgba[(static_cast<std::size_t>(30) * 64 + 5) * 4], 200);
    EXPECT_LT(cell.rgba[(static_cast<std::size_t>(1) * 64 + 0) * 4], 200);
    // Too many lines: the last that fits says how many were left out.
    Image8 small = blank(40, 30, 200), expected = blank(40, 30, 200);
    labelCell(small, {"a", "b", "c", "d", "e"});
    labelCell(expected, {"a", "b", "+3"}); // 30 pixels hold three 9-pixel lines: c, d, e left out
    EXPECT_EQ(small.rgba, expected.rgba);
    Image8 capped = blank(64, 64, 200), two = blank(64, 64, 200);
    labelCell(capped, {"a", "b", "c", "d"}, 2);
    labelCell(two, {"a", "+3"});
    EXPECT_EQ(capped.rgba, two.rgba);
    EXPECT_EQ(labelScale(blank(256, 256)), 2);
}

class SweepSceneTest : public test::DefaultSceneTest {
  protected:
    static std::size_t indexOf(const std::string& id) {
        for (std::size_t i = 0; i < loaded_->scene.placements.size(); ++i)
            if (loaded_->scene.placements[i].id == id) return i;
        throw std::runtime_error("no placement " + id);
    }
};

TEST_F(SweepSceneTest, JointSweepDrivesTheDriverAcrossItsRange) {
    const Scene& scene = loaded_->scene;
    const std::size_t elbow = indexOf("elbow_l");
    const Placement& p = scene.placements[elbow];
    auto sweep = jointSweep(scene, loaded_->model, elbow, 11);
    ASSERT_TRUE(sweep) << sweep.error().message;
    ASSERT_EQ(sweep->steps.size(), 11u);
    auto rest = evaluatePose(loaded_->model, scene.pose);
    ASSERT_TRUE(rest);
    for (std::size_t k = 0; k < 11; ++k) {
        const SweepStep& s = sweep->steps[k];
        EXPECT_NEAR(s.theta, p.thetaMin + (p.thetaMax - p.thetaMin) * k / 10.0, 1e-9);
        EXPECT_NEAR(s.t[elbow], k / 10.0, 1e-4) << k;
        // The step's pose plans a frame with the same t, and only the driver joint moved.
        auto local = evaluatePose(loaded_->model, s.pose);
        ASSERT_TRUE(local);
        auto theta = placementAngle(loaded_->model, *local, p, elbow);
        ASSERT_TRUE(theta);
        EXPECT_NEAR(*theta, s.theta, 1e-3);
        const int driver = findPosable(loaded_->model, p.joint);
        for (std::size_t n = 0; n < local->rotation.size(); ++n)
            if (static_cast<int>(n) != driver)
                EXPECT_LT(glm::length(glm::vec4(local->rotation[n].x - rest->rotation[n].x,
                                                local->rotation[n].y - rest->rotation[n].y,
                                                local->rotation[n].z - rest->rotation[n].z,
                                                local->rotation[n].w - rest->rotation[n].w)),
                          1e-6f)
                    << n;
        Scene posed = scene;
        posed.pose = s.pose;
        auto plan = planFrame(posed, loaded_->model, loaded_->images, loaded_->base);
        ASSERT_TRUE(plan) << plan.error().message;
        for (const BakePlacement& b : plan->heights.placements)
            EXPECT_NEAR(b.t, s.t[static_cast<std::size_t>(b.source)], 1e-9);
    }
    // The biceps bulge on the same joint and axis follows; the other side's elbow does not move.
    EXPECT_GT(sweep->steps.back().t[indexOf("biceps_l")],
              sweep->steps.front().t[indexOf("biceps_l")]);
    EXPECT_EQ(sweep->steps.back().t[indexOf("elbow_r")],
              sweep->steps.front().t[indexOf("elbow_r")]);

    // A reversed range (θmax < θmin) runs the other way; t still goes 0 → 1.
    Scene reversed = scene;
    std::swap(reversed.placements[elbow].thetaMin, reversed.placements[elbow].thetaMax);
    auto back = jointSweep(reversed, loaded_->model, elbow, 3);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->steps[0].t[elbow], 0.0, 1e-4);
    EXPECT_NEAR(back->steps[1].t[elbow], 0.5, 1e-4);
    EXPECT_NEAR(back->steps[2].t[elbow], 1.0, 1e-4);
    EXPECT_NEAR(back->steps[0].theta, p.thetaMax, 1e-9);
}

TEST_F(SweepSceneTest, ClipSweepEqualsActivation) {
    const Scene& scene = loaded_->scene;
    auto act = clipActivation(scene, loaded_->model, "elbow_curl", 10.0);
    ASSERT_TRUE(act);
    const double duration = act->times.back();
    const int steps = static_cast<int>(std::lround(duration * 10.0)) + 1;
    auto sweep = clipSweep(scene, loaded_->model, "elbow_curl", steps);
    ASSERT_TRUE(sweep) << sweep.error().message;
    EXPECT_NEAR(sweep->duration, duration, 1e-6);
    ASSERT_EQ(sweep->steps.size(), act->times.size());
    for (std::size_t k = 0; k < sweep->steps.size(); ++k) {
        EXPECT_NEAR(sweep->steps[k].time, act->times[k], 1e-9);
        for (std::size_t i = 0; i < scene.placements.size(); ++i)
            EXPECT_NEAR(sweep->steps[k].t[i], act->t[i][k], 1e-9) << scene.placements[i].id;
    }
}

TEST_F(SweepSceneTest, BadSweepsNameTheirField) {
    const Scene& scene = loaded_->scene;
    const Model& m = loaded_->model;
    for (int steps : {-1, 0, 1, kMaxSweepSteps + 1}) {
        auto j = jointSweep(scene, m, 0, steps);
        ASSERT_FALSE(j);
        EXPECT_EQ(j.error().field, "steps");
        auto c = clipSweep(scene, m, "squat", steps);
        ASSERT_FALSE(c);
        EXPECT_EQ(c.error().field, "steps");
    }
    auto unknown = clipSweep(scene, m, "moonwalk", 4);
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error().code, ErrorCode::NotFound);
    EXPECT_EQ(unknown.error().field, "clip");
    auto outside = jointSweep(scene, m, scene.placements.size(), 4);
    ASSERT_FALSE(outside);
    EXPECT_EQ(outside.error().field, "placement");
    auto badTime = jointSweep(scene, m, 0, 4, -1.0);
    ASSERT_FALSE(badTime);
    EXPECT_EQ(badTime.error().field, "time");
}

} // namespace
