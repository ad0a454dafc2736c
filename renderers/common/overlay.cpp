// overlay.cpp - drawOverlays() and its integer line and circle algorithms (see overlay.h).
#include "renderers/overlay.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rnd {

using sg::vec3;
using sg::vec4;

namespace overlay {

// Bresenham with the decision variable D = 2*dminor - dmajor (docs/math.md): walk the major
// axis one pixel at a time; step the minor axis when D > 0 (the line passes above the midpoint
// between the two candidates), ties keep the current row. Endpoints are swapped so the walk
// always goes up the major axis: a segment and its reverse give the same pixels.
void bresenham(int x0, int y0, int x1, int y1, const Plot& plot) {
    const bool steep = std::abs(y1 - y0) > std::abs(x1 - x0);
    if (steep) {
        std::swap(x0, y0);
        std::swap(x1, y1);
    }
    if (x0 > x1) {
        std::swap(x0, x1);
        std::swap(y0, y1);
    }
    const long long dx = (long long)x1 - x0, dy = std::llabs((long long)y1 - y0);
    const int ystep = y1 >= y0 ? 1 : -1;
    long long d = 2 * dy - dx;
    for (int x = x0, y = y0;; ++x) {
        if (steep)
            plot(y, x);
        else
            plot(x, y);
        if (x == x1) break;
        if (d > 0) {
            y += ystep;
            d -= 2 * dx;
        }
        d += 2 * dy;
    }
}

std::vector<std::pair<int, int>> bresenhamPixels(int x0, int y0, int x1, int y1) {
    std::vector<std::pair<int, int>> out;
    bresenham(x0, y0, x1, y1, [&](int x, int y) { out.emplace_back(x, y); });
    std::sort(out.begin(), out.end());
    return out;
}

// Midpoint circle: from (0, r) along the first octant (x <= y), decision d = 1 - r (the
// midpoint (x + 1, y - 1/2) against x^2 + y^2 - r^2, scaled), mirrored eight ways.
void midpointCircle(int cx, int cy, int r, const Plot& plot) {
    if (r < 0) return;
    int x = 0, y = r, d = 1 - r;
    while (x <= y) {
        for (auto [a, b] : {std::pair{x, y}, std::pair{y, x}})
            for (int sa : {1, -1})
                for (int sb : {1, -1}) plot(cx + sa * a, cy + sb * b);
        if (d < 0) {
            d += 2 * x + 3;
        } else {
            d += 2 * (x - y) + 5;
            --y;
        }
        ++x;
    }
}

std::vector<std::pair<int, int>> midpointCirclePixels(int cx, int cy, int r) {
    std::vector<std::pair<int, int>> out;
    midpointCircle(cx, cy, r, [&](int x, int y) { out.emplace_back(x, y); });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

// Near-plane clipping before the divide: d = z + w is the signed distance to z = -w, linear
// along the segment, so the crossing is at t = d_a / (d_a - d_b).
bool clipToNear(vec4& a, vec4& b, float* t0, float* t1) {
    const float da = a.z + a.w, db = b.z + b.w;
    if (!(da >= 0 || db >= 0)) return false;   // both behind (or NaN)
    float s0 = 0, s1 = 1;
    if (da < 0) s0 = da / (da - db);
    if (db < 0) s1 = da / (da - db);
    const vec4 na = a + s0 * (b - a), nb = a + s1 * (b - a);
    if (!(na.w > 0 && nb.w > 0)) return false;
    a = na;
    b = nb;
    if (t0) *t0 = s0;
    if (t1) *t1 = s1;
    return true;
}

}   // namespace overlay

namespace {

struct Rgb {
    uint8_t r, g, b;
};
constexpr Rgb kGrid{20, 175, 190}, kAxisX{230, 50, 50}, kAxisY{50, 200, 50}, kAxisZ{60, 100, 245};
constexpr Rgb kLight{255, 210, 40}, kCamera{255, 70, 200}, kBounds{40, 200, 220}, kSelection{255, 140, 0};
constexpr float kDepthBias = 2e-4f;   // lines on a surface (the grid on a floor) stay visible
constexpr int kLightRadius = 6;       // pixels

// A clip-space segment after clipping, in window coordinates (y up, pixel centres at +0.5).
struct WinPoint {
    float x, y, z;
};

// Liang-Barsky of the 2D segment against [lo, hi] in x and y (keeps Bresenham's loop bounded).
bool clipRect(WinPoint& a, WinPoint& b, float loX, float loY, float hiX, float hiY) {
    float t0 = 0, t1 = 1;
    const float dx = b.x - a.x, dy = b.y - a.y;
    auto edge = [&](float p, float q) {   // inside where p*t <= q
        if (p == 0) return q >= 0;
        float t = q / p;
        if (p < 0)
            t0 = std::max(t0, t);
        else
            t1 = std::min(t1, t);
        return t0 <= t1;
    };
    if (!(edge(-dx, a.x - loX) && edge(dx, hiX - a.x) && edge(-dy, a.y - loY) && edge(dy, hiY - a.y))) return false;
    const WinPoint na{a.x + t0 * dx, a.y + t0 * dy, a.z + t0 * (b.z - a.z)}, nb{a.x + t1 * dx, a.y + t1 * dy, a.z + t1 * (b.z - a.z)};
    a = na;
    b = nb;
    return true;
}

class Painter {
public:
    Painter(const sg::FrameInput& f, Framebuffer& fb) : f_(f), fb_(fb) {}

    // World segment a-b: near-clipped, projected, Bresenham; depth-tested when `depthTest`.
    void line(const vec3& a, const vec3& b, Rgb c, bool depthTest) {
        vec4 ca = f_.camera.viewProj * vec4(a, 1.0f), cb = f_.camera.viewProj * vec4(b, 1.0f);
        if (!overlay::clipToNear(ca, cb)) return;
        WinPoint wa = toWindow(ca), wb = toWindow(cb);
        if (!(finite(wa) && finite(wb))) return;   // overflowed: nothing sensible to draw
        if (!clipRect(wa, wb, -1.0f, -1.0f, float(fb_.width) + 1, float(fb_.height) + 1)) return;
        const int x0 = int(std::floor(wa.x)), y0 = int(std::floor(wa.y)), x1 = int(std::floor(wb.x)), y1 = int(std::floor(wb.y));
        const bool xMajor = std::abs(x1 - x0) >= std::abs(y1 - y0);
        const int span = xMajor ? x1 - x0 : y1 - y0;
        overlay::bresenham(x0, y0, x1, y1, [&](int x, int y) {
            const float t = span == 0 ? 0.0f : float(xMajor ? x - x0 : y - y0) / float(span);
            put(x, y, c, depthTest ? std::clamp(wa.z + t * (wb.z - wa.z), 0.0f, 1.0f) : -1.0f);
        });
    }
    // Midpoint circle of `radius` pixels about a world point (always shown).
    void circle(const vec3& centre, int radius, Rgb c) {
        const vec4 p = f_.camera.viewProj * vec4(centre, 1.0f);
        if (!(p.z + p.w >= 0 && p.w > 0)) return;
        const WinPoint w = toWindow(p);
        if (!(std::fabs(w.x) < 1e6f && std::fabs(w.y) < 1e6f)) return;
        overlay::midpointCircle(int(std::floor(w.x)), int(std::floor(w.y)), radius, [&](int x, int y) { put(x, y, c, -1.0f); });
    }
    void box(const sg::Aabb& b, Rgb c, bool depthTest) {
        if (b.empty() || !sg::isFinite(b.min) || !sg::isFinite(b.max)) return;
        auto corner = [&](int k) { return vec3(k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z); };
        for (int k = 0; k < 8; ++k)
            for (int bit : {1, 2, 4})
                if (!(k & bit)) line(corner(k), corner(k | bit), c, depthTest);
    }

private:
    static bool finite(const WinPoint& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }
    WinPoint toWindow(const vec4& c) const {
        const float iw = 1.0f / c.w;
        return {(c.x * iw * 0.5f + 0.5f) * float(fb_.width), (c.y * iw * 0.5f + 0.5f) * float(fb_.height), c.z * iw * 0.5f + 0.5f};
    }
    // Pixel (x, y) counted from the bottom-left; z < 0 means no depth test.
    void put(int x, int y, Rgb c, float z) {
        if (x < 0 || y < 0 || x >= fb_.width || y >= fb_.height) return;
        const int row = fb_.height - 1 - y;
        if (z >= 0 && !(z <= fb_.depth[size_t(row) * fb_.width + x] + kDepthBias)) return;
        uint8_t* p = fb_.pixel(x, row);
        p[0] = c.r;
        p[1] = c.g;
        p[2] = c.b;
        p[3] = 255;
    }
    const sg::FrameInput& f_;
    Framebuffer& fb_;
};

sg::Aabb meshBounds(const sg::DrawMesh& m) { return m.mesh ? m.mesh->bounds().transformed(m.world) : sg::Aabb{}; }

// World bounds of everything drawn, and a size that is never zero.
struct SceneExtent {
    sg::Aabb box;
    float size = 1.0f;   // largest side
};
SceneExtent sceneExtent(const sg::FrameInput& f) {
    SceneExtent e;
    for (const auto& m : f.meshes) e.box.extend(meshBounds(m));
    for (const auto& a : f.analytics) e.box.extend(a.worldBounds);
    if (e.box.empty() || !sg::isFinite(e.box.min) || !sg::isFinite(e.box.max)) e.box = sg::Aabb{vec3(-0.5f), vec3(0.5f)};
    const vec3 s = e.box.extent();
    e.size = std::max({s.x, s.y, s.z});
    if (!(e.size > 1e-6f && e.size < 1e12f)) e.size = 1.0f;
    return e;
}

// 1, 2 or 5 times a power of ten: the smallest with at most 20 cells across `extent`.
float gridSpacing(float extent) {
    const double p = std::pow(10.0, std::floor(std::log10(extent / 20.0)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (extent / (m * p) <= 20.0) return float(m * p);
    return float(10 * p);
}

// Depth-tested unless `onTop`: surfaces in front hide it, a floor at y = 0 does not (kDepthBias).
void drawGrid(Painter& paint, const SceneExtent& e, bool onTop) {
    const float x = std::max(e.box.extent().x, e.box.extent().z);
    const float s = gridSpacing(x > 1e-6f ? x : e.size);
    const long long i0 = std::llround(std::floor(e.box.min.x / s)), i1 = std::llround(std::ceil(e.box.max.x / s));
    const long long k0 = std::llround(std::floor(e.box.min.z / s)), k1 = std::llround(std::ceil(e.box.max.z / s));
    if (i1 - i0 > 200 || k1 - k0 > 200) return;
    for (long long i = i0; i <= i1; ++i) paint.line(vec3(float(i) * s, 0, float(k0) * s), vec3(float(i) * s, 0, float(k1) * s), kGrid, !onTop);
    for (long long k = k0; k <= k1; ++k) paint.line(vec3(float(i0) * s, 0, float(k) * s), vec3(float(i1) * s, 0, float(k) * s), kGrid, !onTop);
}

void drawAxes(Painter& paint, const SceneExtent& e) {
    const float len = 0.5f * e.size;
    paint.line(vec3(0), vec3(len, 0, 0), kAxisX, true);
    paint.line(vec3(0), vec3(0, len, 0), kAxisY, true);
    paint.line(vec3(0), vec3(0, 0, len), kAxisZ, true);
}

// Two unit vectors perpendicular to unit `d` and to each other.
std::pair<vec3, vec3> basisAround(const vec3& d) {
    const vec3 helper = std::fabs(d.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0);
    const vec3 u = glm::normalize(glm::cross(d, helper));
    return {u, glm::cross(d, u)};
}

void drawLight(Painter& paint, const sg::DrawLight& l, const SceneExtent& e) {
    const float len = 0.15f * e.size;
    const vec3 d = glm::length(l.direction) > 0 ? glm::normalize(l.direction) : vec3(0, 0, -1);
    const auto [u, v] = basisAround(d);
    if (l.type == sg::LightType::Directional) {   // an arrow from outside the scene along d
        const vec3 tail = e.box.center() - d * (0.6f * e.size), head = tail + d * len;
        paint.line(tail, head, kLight, false);
        for (const vec3& side : {u, -u, v, -v}) paint.line(head, head - d * (0.3f * len) + side * (0.15f * len), kLight, false);
        return;
    }
    paint.circle(l.position, kLightRadius, kLight);
    if (l.type != sg::LightType::Spot) return;
    const float c = std::clamp(l.cosOuter, -1.0f, 1.0f), s = std::sqrt(std::max(0.0f, 1 - c * c));
    for (const vec3& side : {u, -u, v, -v}) paint.line(l.position, l.position + len * (c * d + s * side), kLight, false);
}

void drawCamera(Painter& paint, const CameraGizmo& cam, const SceneExtent& e) {
    const float depth = 0.1f * e.size;
    const bool persp = cam.projection.type == sg::ProjectionType::Perspective;
    const float h = persp ? depth * std::tan(0.5f * glm::radians(std::clamp(cam.projection.fovyDeg, 1.0f, 179.0f))) : 0.5f * depth;
    const float w = h * std::clamp(cam.aspect, 0.01f, 100.0f);
    auto world = [&](float x, float y, float z) { return vec3(cam.world * vec4(x, y, z, 1.0f)); };
    const vec3 eye = world(0, 0, 0);
    const vec3 c[4] = {world(-w, -h, -depth), world(w, -h, -depth), world(w, h, -depth), world(-w, h, -depth)};
    for (int k = 0; k < 4; ++k) {
        paint.line(persp ? eye : c[k] + vec3(cam.world * vec4(0, 0, depth, 0)), c[k], kCamera, false);
        paint.line(c[k], c[(k + 1) % 4], kCamera, false);
    }
    paint.line(world(-0.5f * w, h, -depth), world(0, 1.5f * h, -depth), kCamera, false);   // "up" tick
    paint.line(world(0.5f * w, h, -depth), world(0, 1.5f * h, -depth), kCamera, false);
}

void drawSelection(Painter& paint, const sg::FrameInput& f, const std::vector<sg::NodeId>& selected) {
    auto isSelected = [&](sg::NodeId n) { return n != sg::kNoNode && std::find(selected.begin(), selected.end(), n) != selected.end(); };
    for (const auto& m : f.meshes)
        if (isSelected(m.node)) paint.box(meshBounds(m), kSelection, false);
    for (const auto& a : f.analytics)
        if (isSelected(a.node)) paint.box(a.worldBounds, kSelection, false);
}

}   // namespace

const char* overlayNameList() { return "grid, axes, lights, cameras, bounds, selection, grid-on-top"; }

bool parseOverlayList(const std::string& list, OverlayOptions& out, std::string& err) {
    std::stringstream in(list);
    for (std::string name; std::getline(in, name, ',');) {
        if (name == "grid-on-top") {
            out.grid = out.gridOnTop = true;
            continue;
        }
        bool* flag = name == "grid"        ? &out.grid
                     : name == "axes"      ? &out.axes
                     : name == "lights"    ? &out.lights
                     : name == "cameras"   ? &out.cameras
                     : name == "bounds"    ? &out.bounds
                     : name == "selection" ? &out.selection
                                           : nullptr;
        if (!flag) {
            err = "--overlay: '" + name + "' is not one of " + overlayNameList();
            return false;
        }
        *flag = true;
    }
    if (list.empty() || list.back() == ',') {
        err = std::string("--overlay: expected a comma-separated list of ") + overlayNameList();
        return false;
    }
    return true;
}

void drawOverlays(const sg::FrameInput& frame, const OverlayOptions& o, Framebuffer& fb) {
    if (!o.any() || fb.width <= 0 || fb.height <= 0 || fb.depth.size() != size_t(fb.width) * fb.height || fb.color.size() != fb.depth.size() * 4 ||
        !sg::isFinite(frame.camera.viewProj))
        return;
    Painter paint(frame, fb);
    const SceneExtent e = sceneExtent(frame);
    if (o.grid) drawGrid(paint, e, o.gridOnTop);
    if (o.bounds) {
        for (const auto& m : frame.meshes) paint.box(meshBounds(m), kBounds, true);
        for (const auto& a : frame.analytics) paint.box(a.worldBounds, kBounds, true);
    }
    if (o.axes) drawAxes(paint, e);
    if (o.cameras)
        for (const CameraGizmo& c : o.cameraGizmos)   // not the camera the frame is seen through
            if (glm::length(vec3(c.world[3]) - frame.camera.eye) > 1e-4f * e.size) drawCamera(paint, c, e);
    if (o.lights)
        for (const sg::DrawLight& l : frame.lights) drawLight(paint, l, e);
    if (o.selection) drawSelection(paint, frame, o.selected);
}

void setSceneOverlayInputs(const sg::Scene& scene, const std::vector<sg::NodeId>& nodes, float aspect, OverlayOptions& o) {
    o.selected.clear();
    o.cameraGizmos.clear();
    std::vector<uint8_t> inside(scene.idCapacity(), 0);   // selected, or under a selected node
    bool any = false;
    for (sg::NodeId n : nodes)
        if (scene.valid(n)) inside[n] = 1, any = true;
    if (any)
        for (sg::NodeId n : scene.depthFirstOrder()) {   // parents come first
            const sg::NodeId p = scene.node(n).parent;
            if (!inside[n] && scene.valid(p) && inside[p]) inside[n] = 1;
            if (inside[n]) o.selected.push_back(n);
        }
    for (sg::NodeId id : scene.cameras())
        if (const auto* cam = std::get_if<sg::Camera>(&scene.node(id).payload)) o.cameraGizmos.push_back({scene.world(id), cam->projection, aspect});
}

}   // namespace rnd
