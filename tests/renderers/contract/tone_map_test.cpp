// tone_map_test.cpp - the display transform's scalar implementation (renderers/tone_map.h), the
// one every CPU backend calls and the GL shader mirrors: each operator at known inputs (0, 0.18,
// 1, 10, a large value, grey and coloured) against the published formulas evaluated
// independently in double precision (tests/renderers/conformance/conformance_formulas.h), a few values
// the specifications state outright, the curves' range and order, and exposure: +1 EV doubles
// the linear output, and exposure 0 with no operator returns the colour bit for bit.
#include "renderers/tone_map.h"

#include "conformance_formulas.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using sg::vec3;

namespace {

std::array<double, 3> toArray(const vec3& c) { return {c.x, c.y, c.z}; }

// Inputs where the curves have their character: black, mid grey, white, a highlight ten times
// white, a huge value; then colours: saturated, dark (Neutral's offset region), bright.
const std::vector<vec3>& inputs() {
    static const std::vector<vec3> v = {vec3(0.0f),
                                        vec3(0.18f),
                                        vec3(1.0f),
                                        vec3(10.0f),
                                        vec3(1e4f),
                                        vec3(0.9f, 0.3f, 0.05f),
                                        vec3(0.02f, 0.05f, 0.07f),
                                        vec3(2.4f, 0.5f, 0.05f),
                                        vec3(0.5f, 0.3f, 0.1f),
                                        vec3(30.0f, 2.0f, 0.0f)};
    return v;
}

void expectNear(const vec3& got, const std::array<double, 3>& want, double tol, const char* what, const vec3& input) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c], want[size_t(c)], tol) << what << " of (" << input.x << ", " << input.y << ", " << input.z << "), channel " << c;
}

}   // namespace

TEST(ToneMapTest, AcesMatchesTheFittedCurveAtKnownInputs) {
    for (const vec3& c : inputs()) expectNear(rnd::toneMapAces(c), conformance::acesReference(toArray(c)), 2e-6, "ACES", c);
    // Values of the fit (input / 0.6 through the matrices and the rational RRT + ODT), grey in.
    EXPECT_EQ(rnd::toneMapAces(vec3(0.0f)), vec3(0.0f)) << "black stays black (the fit's -0.00038 clamps to 0)";
    EXPECT_NEAR(rnd::toneMapAces(vec3(0.18f)).g, 0.213105, 1e-5);
    EXPECT_NEAR(rnd::toneMapAces(vec3(1.0f)).g, 0.763397, 1e-5);
    EXPECT_NEAR(rnd::toneMapAces(vec3(10.0f)).g, 0.991006, 1e-5);
    EXPECT_EQ(rnd::toneMapAces(vec3(1e4f)), vec3(1.0f)) << "clamped at white";
}

TEST(ToneMapTest, KhrNeutralMatchesTheSpecificationAtKnownInputs) {
    for (const vec3& c : inputs()) expectNear(rnd::toneMapKhrNeutral(c), conformance::khrNeutralReference(toArray(c)), 2e-6, "Neutral", c);
    // The specification's guarantee: inside [0.08, 0.8]^3 the output is the input less 0.04.
    for (const vec3& c : {vec3(0.18f), vec3(0.5f, 0.3f, 0.1f), vec3(0.08f, 0.8f, 0.4f)}) {
        const vec3 out = rnd::toneMapKhrNeutral(c);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[k], c[k] - 0.04f, 1e-6f) << k;
    }
    // Below 0.08 the offset is x - 6.25 x^2 (grey 0.05: 0.05 - 0.015625 = 0.034375 off).
    EXPECT_NEAR(rnd::toneMapKhrNeutral(vec3(0.05f)).r, 0.015625f, 1e-7f);
    EXPECT_EQ(rnd::toneMapKhrNeutral(vec3(0.0f)), vec3(0.0f));
    // White: peak 0.96 compresses to 1 - 0.24^2 / 0.44 = 0.869091 (grey: no desaturation to do).
    EXPECT_NEAR(rnd::toneMapKhrNeutral(vec3(1.0f)).b, 0.8690909, 1e-6);
    EXPECT_NEAR(rnd::toneMapKhrNeutral(vec3(10.0f)).b, 0.9938983, 1e-6);
    EXPECT_NEAR(rnd::toneMapKhrNeutral(vec3(1e4f)).b, 0.9999942, 1e-6);
}

// Both operators map [0, inf) into [0, 1] and keep the order of greys.
TEST(ToneMapTest, CurvesAreMonotonicAndBounded) {
    for (sg::ToneMapping op : {sg::ToneMapping::Aces, sg::ToneMapping::KhrNeutral}) {
        float last = -1.0f;
        for (double x = 1e-5; x < 1e5; x *= 1.05) {
            const vec3 y = rnd::toneMap(op, vec3(float(x)));
            EXPECT_GE(y.g, last) << sg::toString(op) << " at " << x;
            EXPECT_GE(y.g, 0.0f);
            EXPECT_LE(y.g, 1.0f);
            last = y.g;
        }
    }
}

TEST(ToneMapTest, ExposureScalesTheLinearColourBeforeTheOperator) {
    EXPECT_EQ(rnd::exposureScale(0.0f), 1.0f);
    EXPECT_EQ(rnd::exposureScale(1.0f), 2.0f);
    EXPECT_EQ(rnd::exposureScale(-3.0f), 0.125f);
    const vec3 c(0.1f, 0.25f, 0.4f);
    // +1 EV doubles the linear output (no operator), exactly.
    EXPECT_EQ(rnd::displayTransform(c, rnd::exposureScale(1.0f), sg::ToneMapping::None), 2.0f * c);
    sg::RenderSettings s;
    s.exposure = 1.0f;
    EXPECT_EQ(rnd::DisplayTransform(s)(c), 2.0f * c);
    s.exposure = -1.0f;
    EXPECT_EQ(rnd::DisplayTransform(s)(c), 0.5f * c);
    // With an operator, the exposure comes first: T(2^EV c).
    s.exposure = 1.5f;
    s.toneMapping = sg::ToneMapping::Aces;
    const vec3 got = rnd::DisplayTransform(s)(c);
    expectNear(got, conformance::acesReference(toArray(float(std::pow(2.0, 1.5)) * c)), 2e-6, "ACES at +1.5 EV", c);
    // Negative light (never produced, but a filter could ring) counts as black.
    EXPECT_EQ(rnd::displayTransform(vec3(-1.0f), 1.0f, sg::ToneMapping::None), vec3(0.0f));
}

// The default settings are the identity, and the identity hands the colour back untouched (the
// backends' fast paths, and their images bit for bit as before).
TEST(ToneMapTest, DefaultsAreTheIdentity) {
    const sg::RenderSettings s;
    EXPECT_TRUE(s.displayTransformIsIdentity());
    const rnd::DisplayTransform d(s);
    EXPECT_TRUE(d.identity);
    for (const vec3& c : {vec3(-0.5f, 2.0f, 1e30f), vec3(0.1f, 0.2f, 0.3f)}) {
        const vec3 out = d(c);
        EXPECT_EQ(std::memcmp(&out, &c, sizeof c), 0);
    }
    sg::RenderSettings t;
    t.toneMapping = sg::ToneMapping::KhrNeutral;
    EXPECT_FALSE(t.displayTransformIsIdentity());
    t = {};
    t.exposure = 0.5f;
    EXPECT_FALSE(t.displayTransformIsIdentity());
}
