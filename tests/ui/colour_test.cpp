// colour_test.cpp - colours as the user sees them: the colour editors show sRGB-encoded values
// of the linear colours the scene stores, so the background swatch matches the viewport's
// pixels; every 8-bit value the editor can show or take round-trips, and a value set by name
// shows as the bytes it was made from.
#include "ui/colour.h"
#include "ui/viewer_state.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace ui;

namespace {
int byteOf(float encoded) { return int(std::lround(encoded * 255.0f)); }
}   // namespace

TEST(ColourTest, SrgbTransferFunctionAtKnownPoints) {
    EXPECT_FLOAT_EQ(srgbFromLinear(0.0f), 0.0f);
    EXPECT_NEAR(srgbFromLinear(1.0f), 1.0f, 1e-6f);
    EXPECT_NEAR(srgbFromLinear(0.5f), 0.7354f, 1e-4f);
    EXPECT_NEAR(linearFromSrgb(80.0f / 255.0f), 0.0802f, 1e-4f) << "the viewport's (80, 85, 93) background is linear 0.08";
    EXPECT_NEAR(srgbFromLinear(0.002f), 12.92f * 0.002f, 1e-7f) << "the linear toe";
    EXPECT_FLOAT_EQ(srgbFromLinear(-0.5f), 0.0f);
    EXPECT_FLOAT_EQ(linearFromSrgb(-0.5f), 0.0f);
}

TEST(ColourTest, EveryByteRoundTripsAndHdrValuesSurvive) {
    for (int i = 0; i <= 255; ++i) EXPECT_EQ(byteOf(srgbFromLinear(linearFromSrgb(float(i) / 255.0f))), i) << i;
    for (float v : {0.0f, 0.001f, 0.08f, 0.5f, 1.0f, 4.0f, 20.0f}) EXPECT_NEAR(linearFromSrgb(srgbFromLinear(v)), v, 1e-5f * std::max(v, 1.0f)) << v;
    EXPECT_GT(srgbFromLinear(4.0f), 1.0f) << "HDR light colours stay above 1 (the editor switches to floats)";
}

TEST(ColourTest, ABackgroundSetByNameShowsAsTheBytesItWasMadeFrom) {
    ViewerState st;
    st.setScene(sg::Scene{}, {});
    sg::vec3 linear = linearFromSrgb(sg::vec3(80.0f, 85.0f, 93.0f) / 255.0f);
    char value[128];
    std::snprintf(value, sizeof value, "[%.7f,%.7f,%.7f]", linear.x, linear.y, linear.z);
    ASSERT_EQ(st.setByName("background", value), "");
    sg::vec3 shown = srgbFromLinear(st.doc.scene.settings.background);
    EXPECT_EQ(byteOf(shown.x), 80);
    EXPECT_EQ(byteOf(shown.y), 85);
    EXPECT_EQ(byteOf(shown.z), 93);
    // Editing it in the editor to the same bytes stores the same linear value.
    sg::vec3 back = linearFromSrgb(sg::vec3(80.0f, 85.0f, 93.0f) / 255.0f);
    EXPECT_NEAR(back.x, st.doc.scene.settings.background.x, 1e-6f);
    EXPECT_NEAR(back.z, st.doc.scene.settings.background.z, 1e-6f);
}
