// aov_set_test.cpp - the AOVs (renderers/aov.h): one name each, parsed back to the same AOV,
// the set's operations, and Normal and Id rendered from the visibility. Needs nothing.
#include "renderers/aov.h"
#include "renderers/framebuffer.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace {

using rnd::Aov;
using rnd::AovSet;

TEST(AovNames, EveryAovHasItsOwnNameThatParsesBack) {
    std::set<std::string> seen;
    for (Aov a : rnd::kAllAovs) {
        const std::string_view n = rnd::nameOf(a);
        EXPECT_FALSE(n.empty());
        EXPECT_TRUE(seen.insert(std::string(n)).second) << n << " twice";
        Aov back{};
        ASSERT_TRUE(rnd::parseAov(n, back)) << n;
        EXPECT_EQ(back, a) << n;
    }
    Aov none{};
    EXPECT_FALSE(rnd::parseAov("colour", none));
    EXPECT_FALSE(rnd::parseAov("", none));
    EXPECT_EQ(rnd::nameOf(Aov::TraversalCost), "cost") << "as the diagnostic view that shows it";
}

TEST(AovSetTest, AddRemoveAndList) {
    AovSet s;
    EXPECT_TRUE(s.empty());
    s.add(Aov::Overdraw).add(Aov::Depth);
    EXPECT_TRUE(s.has(Aov::Depth) && s.has(Aov::Overdraw));
    EXPECT_FALSE(s.has(Aov::Visibility));
    EXPECT_EQ(s.names(), (std::vector<std::string_view>{"depth", "overdraw"})) << "in the enum's order";
    EXPECT_TRUE(s.hasAll({Aov::Depth}));
    EXPECT_FALSE(s.hasAll({Aov::Depth, Aov::Id}));
    EXPECT_TRUE(s.hasAll({}));
    s.set(Aov::Overdraw, false).set(Aov::Id, true);
    EXPECT_EQ(s, (AovSet{Aov::Id, Aov::Depth}));
    EXPECT_EQ(s.without(Aov::Depth).list(), std::vector<Aov>{Aov::Id});
    EXPECT_TRUE(s.remove(Aov::Id).remove(Aov::Depth).empty());
}

TEST(AovSetTest, NormalAndIdAreRenderedFromTheVisibility) {
    EXPECT_EQ(rnd::renderedAovs({Aov::Normal}), (AovSet{Aov::Visibility}));
    EXPECT_EQ(rnd::renderedAovs({Aov::Depth, Aov::Id}), (AovSet{Aov::Depth, Aov::Visibility}));
    EXPECT_EQ(rnd::renderedAovs({Aov::Overdraw, Aov::TraversalCost}), (AovSet{Aov::Overdraw, Aov::TraversalCost}));
    EXPECT_TRUE(rnd::renderedAovs({}).empty());
}

TEST(AovFramebuffer, AllocateMakesEachAovPresentAtTheImageSize) {
    rnd::Framebuffer fb;
    fb.resize(4, 3);
    EXPECT_TRUE(fb.has(Aov::Depth));
    for (Aov a : {Aov::Visibility, Aov::Overdraw, Aov::TraversalCost, Aov::Normal, Aov::Id}) EXPECT_FALSE(fb.has(a)) << rnd::nameOf(a);
    for (Aov a : rnd::kAllAovs) fb.allocate(a);
    for (Aov a : rnd::kAllAovs) EXPECT_TRUE(fb.has(a)) << rnd::nameOf(a);
    EXPECT_EQ(fb.drawable.size(), 12u);
    EXPECT_EQ(fb.primitive[0], rnd::kNoPrimitive);
    EXPECT_EQ(fb.costPrims.size(), 12u);
    fb.resize(2, 2);
    EXPECT_TRUE(fb.has(Aov::Depth));
    EXPECT_FALSE(fb.has(Aov::Visibility)) << "resize drops the visibility and the counters";
    EXPECT_FALSE(fb.has(Aov::Overdraw));
    EXPECT_FALSE(fb.has(Aov::TraversalCost));
}

}   // namespace
