// demo_test.cpp - the bundled demo scene (assets/demo.h) has what the product promises at first
// launch: every kind of content (meshes, textures, lights, cameras, implicit shapes, quadrics,
// CSG, parametric surfaces, density grids).
#include "assets/demo.h"
#include "scenegraph/frame.h"

#include <gtest/gtest.h>

TEST(DemoSceneTest, ContainsEveryKindOfContent) {
    sg::Scene s = assets::makeDemoScene();
    int meshes = 0, lights = 0, cameras = 0, implicits = 0, quadrics = 0, csg = 0, parametric = 0, grids = 0, textured = 0;
    for (sg::NodeId id : s.depthFirstOrder()) {
        const auto& p = s.node(id).payload;
        if (auto* m = std::get_if<sg::MeshInstance>(&p)) {
            ++meshes;
            if (s.material(m->material).diffuseTexture >= 0) ++textured;
        }
        lights += std::holds_alternative<sg::Light>(p);
        cameras += std::holds_alternative<sg::Camera>(p);
        csg += std::holds_alternative<sg::CsgPayload>(p);
        parametric += std::holds_alternative<sg::ParametricPayload>(p);
        grids += std::holds_alternative<sg::GridPayload>(p);
        if (auto* i = std::get_if<sg::ImplicitPayload>(&p)) {
            ++implicits;
            quadrics += i->shape.type == sg::ImplicitType::Quadric;
        }
    }
    EXPECT_GE(meshes, 4);
    EXPECT_GE(textured, 2);
    EXPECT_GE(lights, 3);
    EXPECT_EQ(cameras, 1);
    EXPECT_GE(implicits, 4);
    EXPECT_GE(quadrics, 1);
    EXPECT_GE(csg, 1);
    EXPECT_GE(parametric, 1);
    EXPECT_GE(grids, 1);
    EXPECT_TRUE(s.valid(s.activeCamera));

    sg::FrameInput f = sg::flatten(s, 16.0f / 9.0f);
    EXPECT_EQ(f.lights.size(), size_t(lights));
    EXPECT_GE(f.analytics.size(), 6u);   // CSG children fold into one drawable
    bool hasCsg = false;
    for (const auto& a : f.analytics) hasCsg |= a.kind == sg::DrawAnalytic::Kind::Csg;
    EXPECT_TRUE(hasCsg);
    // The camera sees the room: the scene's centre projects inside the image.
    sg::vec4 c = f.camera.viewProj * sg::vec4(0, 0.8f, 0, 1);
    EXPECT_GT(c.w, 0);
    EXPECT_LT(std::abs(c.x / c.w), 1.0f);
    EXPECT_LT(std::abs(c.y / c.w), 1.0f);
}
