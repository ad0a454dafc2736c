// tess_dump.cpp - debug tool: tessellates the demo scene's analytic drawables and writes
// OUTDIR/<node>.obj and OUTDIR/<node>.png (orthographic z-buffer preview, Lambert shading
// from interpolated vertex normals; back-facing triangles are drawn red).
//   build/release/tests/renderers/tessellate/tess_dump /tmp/tess 64
#include "renderers/tessellate.h"

#include "assets/demo.h"
#include "assets/image_io.h"

#include <chrono>
#include <cstdio>
#include <fstream>

using namespace sg;

static void writeObj(const Mesh& m, const std::string& path) {
    std::ofstream f(path);
    for (const vec3& p : m.positions) f << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (const vec3& n : m.normals) f << "vn " << n.x << ' ' << n.y << ' ' << n.z << '\n';
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
        f << "f " << m.indices[i] + 1 << "//" << m.indices[i] + 1 << ' ' << m.indices[i + 1] + 1 << "//" << m.indices[i + 1] + 1 << ' '
          << m.indices[i + 2] + 1 << "//" << m.indices[i + 2] + 1 << '\n';
}

static void preview(const rnd::Tessellation& t, const mat4& world, const Material& mat, const std::string& path) {
    const int W = 512;
    const Mesh& m = *t.mesh;
    mat4 view = glm::lookAt(vec3(1.0f, 0.8f, 1.3f), vec3(0.0f), vec3(0, 1, 0));
    std::vector<vec3> p(m.positions.size()), n(m.positions.size());
    mat3 nm = normalMatrix(world);
    Aabb b;
    for (size_t i = 0; i < p.size(); ++i) {
        p[i] = vec3(view * world * vec4(m.positions[i], 1.0f));
        n[i] = glm::normalize(mat3(view) * nm * m.normals[i]);
        b.extend(p[i]);
    }
    float s = 0.9f * W / std::max(b.extent().x, b.extent().y);
    vec3 c = b.center();
    for (vec3& q : p) q = vec3((q.x - c.x) * s + W / 2, (q.y - c.y) * s + W / 2, q.z);
    std::vector<float> z(W * W, -1e30f);
    std::vector<uint8_t> rgba(W * W * 4, 40);
    vec3 light = glm::normalize(vec3(0.3f, 0.6f, 1.0f));
    for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
        uint32_t i0 = m.indices[k], i1 = m.indices[k + 1], i2 = m.indices[k + 2];
        vec3 a = p[i0], bb = p[i1], cc = p[i2];
        float area = (bb.x - a.x) * (cc.y - a.y) - (bb.y - a.y) * (cc.x - a.x);
        if (area == 0) continue;
        bool back = area < 0;
        vec3 base = mat.baseColor;
        if (!t.triangleMaterial.empty()) base = t.materials[t.triangleMaterial[k / 3]].baseColor;
        int x0 = std::max(0, int(std::min({a.x, bb.x, cc.x}))), x1 = std::min(W - 1, int(std::max({a.x, bb.x, cc.x})) + 1);
        int y0 = std::max(0, int(std::min({a.y, bb.y, cc.y}))), y1 = std::min(W - 1, int(std::max({a.y, bb.y, cc.y})) + 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                float px = x + 0.5f, py = y + 0.5f;
                float w0 = ((bb.x - px) * (cc.y - py) - (bb.y - py) * (cc.x - px)) / area;
                float w1 = ((cc.x - px) * (a.y - py) - (cc.y - py) * (a.x - px)) / area;
                float w2 = 1 - w0 - w1;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                float zz = w0 * a.z + w1 * bb.z + w2 * cc.z;
                int idx = (W - 1 - y) * W + x;
                if (zz <= z[idx]) continue;
                z[idx] = zz;
                vec3 nn = glm::normalize(w0 * n[i0] + w1 * n[i1] + w2 * n[i2]);
                vec3 col = back ? vec3(1, 0, 0) : base * (0.15f + 0.85f * std::max(glm::dot(nn, light), 0.0f));
                for (int ch = 0; ch < 3; ++ch) rgba[idx * 4 + ch] = uint8_t(std::clamp(std::pow(col[ch], 1 / 2.2f), 0.0f, 1.0f) * 255);
                rgba[idx * 4 + 3] = 255;
            }
    }
    assets::writePng(path, W, W, rgba.data(), true);
}

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: tess_dump OUTDIR [resolution]\n");
        return 2;
    }
    std::string dir = argv[1];
    int res = argc > 2 ? std::atoi(argv[2]) : 64;
    Scene s = assets::makeDemoScene();
    FrameInput f = flatten(s, 1.0f);
    for (const DrawAnalytic& a : f.analytics) {
        auto t0 = std::chrono::steady_clock::now();
        rnd::Tessellation t = rnd::tessellate(a, res);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::string name = s.node(a.node).name;
        for (char& ch : name)
            if (ch == ' ') ch = '_';
        std::printf("%-16s %8zu triangles %8.1f ms\n", name.c_str(), t.mesh->triangleCount(), ms);
        writeObj(*t.mesh, dir + "/" + name + ".obj");
        preview(t, t.worldSpace ? mat4(1.0f) : a.world, a.material, dir + "/" + name + ".png");
    }
}
