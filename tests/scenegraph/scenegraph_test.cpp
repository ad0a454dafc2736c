#include <gtest/gtest.h>
#include "scenegraph/scene.h"
TEST(SceneTest, Root) { sg::Scene s; EXPECT_EQ(s.nodeCount(), 1u); }
