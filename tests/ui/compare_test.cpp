// compare_test.cpp - the split and difference views' backends (defaults compare different
// backends, chosen from the registry; each view keeps its own choice), the difference figures'
// one spelling (the Compare tab, the overlay and `print diff` agree; 100% only when every pixel
// is within) and the heat map's legend.
#include "ui/viewer_state.h"

#include "headless_ui.h"
#include "renderers/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

using namespace ui;

TEST(CompareTest, DefaultsStartFromTheShownBackendAndCompareDifferentOnes) {
    std::vector<std::string> names = rnd::rendererNames();
    ASSERT_GE(names.size(), 2u);
    for (const std::string& first : names) {
        SCOPED_TRACE(first);
        std::vector<std::string> all = comparisonBackends(first, names.size());
        EXPECT_EQ(all.front(), first);
        EXPECT_EQ(std::set<std::string>(all.begin(), all.end()).size(), names.size()) << "every registered backend once";
        std::vector<std::string> pair = comparisonBackends(first, 2);
        EXPECT_NE(pair[0], pair[1]);
    }
    EXPECT_EQ(comparisonBackends(names[0], 5).size(), 5u);   // more than registered: the last repeats
}

TEST(CompareTest, EachViewKeepsItsOwnBackends) {
    std::vector<std::string> names = rnd::rendererNames();
    ASSERT_GE(names.size(), 3u);
    ViewerState st;
    st.setBackend(names[1]);
    st.showView(ViewMode::Difference);
    std::vector<std::string> diff = visibleBackends(st);
    ASSERT_EQ(diff.size(), 2u);
    EXPECT_EQ(diff[0], names[1]);
    EXPECT_NE(diff[1], diff[0]);

    st.setBackend(names[2]);
    st.showView(ViewMode::Split, 3);
    std::vector<std::string> split = visibleBackends(st);
    ASSERT_EQ(split.size(), 3u);
    EXPECT_EQ(split[0], names[2]);
    EXPECT_EQ(std::set<std::string>(split.begin(), split.end()).size(), 3u);

    st.showView(ViewMode::Difference);
    EXPECT_EQ(visibleBackends(st), diff) << "the difference view kept its pair";
    st.view.compare.diff[1] = names[2];   // a choice in the Compare tab
    st.showView(ViewMode::Split, 2);
    EXPECT_EQ(visibleBackends(st), std::vector<std::string>(split.begin(), split.begin() + 2)) << "the split view did not follow it";
    st.showView(ViewMode::Difference);
    EXPECT_EQ(visibleBackends(st)[1], names[2]);
    EXPECT_EQ(st.viewName(), "difference");

    ViewerState fresh;   // a mode set directly, without showView: the defaults, never ""
    fresh.view.compare.mode = ViewMode::Split;
    for (const std::string& b : visibleBackends(fresh)) EXPECT_FALSE(b.empty());
}

TEST(CompareTest, FiguresHaveOneSpellingAndNeverRoundUpTo100) {
    DiffFigures d;
    d.valid = true;
    d.mean = 0.1234;
    d.max = 37;
    d.psnr = 48.25;
    d.within = 0.99997;   // 3 pixels in 100000 differ
    EXPECT_EQ(d.withinText(), "99.99%");
    EXPECT_EQ(d.meanText(), "0.12");
    EXPECT_EQ(d.psnrText(), "48.2 dB");
    EXPECT_EQ(d.summary("a", "b", 8), "|a - b|   mean 0.12   max 37   PSNR 48.2 dB   within 8: 99.99%");
    d.within = 0.9997;
    EXPECT_EQ(d.withinText(), "99.97%");
    d.within = 0.5;
    EXPECT_EQ(d.withinText(), "50.00%");
    d.within = 1.0;
    EXPECT_EQ(d.withinText(), "100%");
    d.psnr = std::numeric_limits<double>::infinity();
    EXPECT_EQ(d.psnrText(), "identical");
    d.valid = false;
    EXPECT_EQ(d.summary("a", "b", 8), "|a - b|");
}

TEST(CompareTest, HeatMapHasALegend) {
    Headless h;
    h.st.showView(ViewMode::Difference);
    h.view.slots.resize(2);
    h.frame();
    EXPECT_EQ(h.st.hooks.itemRects.count("diff/legend"), 0u) << "no heat map yet: no legend";
    static int fakeTexture = 0;
    h.view.diff.texture = &fakeTexture;
    h.view.diff.width = h.view.diff.height = 8;
    h.st.view.diff.valid = true;
    h.frame();
    ASSERT_EQ(h.st.hooks.itemRects.count("diff/legend"), 1u);
    const ItemRect& legend = h.rect("diff/legend");
    const ItemRect& vp = h.rect("viewport");
    EXPECT_GT(legend.x1 - legend.x0, 100.0f);
    EXPECT_GE(legend.x0, vp.x0);
    EXPECT_LE(legend.x1, vp.x1);
}
