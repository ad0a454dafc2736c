// raster_shading.cpp - the CPU rasterizer's batched lighting (raster_shading.h): ShadeBatch's
// sizing and padding, the run-time choice of AVX2 or SSE2, and shadeBatch itself, whose body is
// shade_kernel.inl (Phong, Blinn-Phong) or pbr_kernel.inl (pbr) compiled once per instruction
// set (a scalar loop over rnd::lightTerms or the pbr terms where neither is available).
#include "raster/raster_shading.h"
#include "renderers/debug_switches.h"

#include "raster/simd.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace rnd::raster {

void ShadeBatch::resize(size_t n) {
    size = n;
    // Whole vectors of 8 (the AVX2 kernel), and kSlack more for writers that store whole vectors
    // past the end (tile_kernels.h's preparePlainRun; pad() then restores the padding).
    const size_t cap = ((n + 7) & ~size_t(7)) + kSlack;
    for (auto* v : {&px, &py, &pz, &nx, &ny, &nz, &ar, &ag, &ab, &sr, &sg, &sb, &kd, &ks, &shin, &cr, &cg, &cb})
        if (v->size() < cap) v->resize(cap, 0.0f);
    if (mat.size() < cap) mat.resize(cap, -1);
    mats.clear();
    visLights = visStride = 0;
    pad();
}

void ShadeBatch::pad() {
    // Padding lanes up to the next multiple of 8: harmless values (normal up, zero coefficients).
    const size_t end = (size + 7) & ~size_t(7);
    for (size_t i = size; i < end; ++i) {
        px[i] = py[i] = pz[i] = 0;
        nx[i] = nz[i] = 0;
        ny[i] = 1;
        kd[i] = ks[i] = 0;
        shin[i] = 1;
        mat[i] = -1;
    }
}

bool useAvx2() {
#if defined(RASTER_HAVE_AVX2)
    static const bool use = [] {
        if (debugSwitches().rasterForceSse) return false;
        __builtin_cpu_init();
        return bool(__builtin_cpu_supports("avx2"));
    }();
    return use;
#else
    return false;
#endif
}

namespace {
// What the pbr kernel reads of the environment, once per batch: the prefiltered levels, the
// harmonics with the intensity in them, the rotation, the split-sum table.
struct PbrKernelEnv {
    static constexpr int kLevels = EnvironmentMap::kLevels;
    struct Level {
        const float* rgb = nullptr;
        int width = 0, height = 0;
    };
    bool on = false;
    Level levels[kLevels];
    float sh[3][9] = {};
    float intensity = 1.0f, cosRot = 1.0f, sinRot = 0.0f;
    const float* splitSum = nullptr;

    explicit PbrKernelEnv(const EnvironmentLight* env) {
        if (!env || !env->map) return;
        on = true;
        for (int k = 0; k < kLevels; ++k) {
            const EnvironmentMap::Level& l = env->map->level(k);
            levels[k] = {l.rgb.data(), l.width, l.height};
        }
        for (int i = 0; i < 9; ++i)
            for (int c = 0; c < 3; ++c) sh[c][i] = env->intensity * env->map->sh()[size_t(i)][c];
        intensity = env->intensity;
        cosRot = env->cosRot;
        sinRot = env->sinRot;
        splitSum = &splitSumTable()[0].x;
    }
};
}   // namespace

#if defined(RASTER_HAVE_SSE2)
namespace kern_sse {
using namespace simd_sse;
#include "raster/pbr_kernel.inl"
#include "raster/shade_kernel.inl"
#include "raster/shadow_kernel.inl"
}   // namespace kern_sse

#if defined(RASTER_HAVE_AVX2)
VIEWER_ISA_REGION_BEGIN("avx2")
namespace kern_avx2 {
using namespace simd_avx2;
#include "raster/pbr_kernel.inl"
#include "raster/shade_kernel.inl"
#include "raster/shadow_kernel.inl"
void shadeBatchAvx2(ShadeBatch& b, size_t n, const sg::FrameInput& f) { shadeKernel(b, n, f); }
void shadePbrAvx2(ShadeBatch& b, size_t n, const sg::FrameInput& f, const PbrKernelEnv& env) { shadePbrKernel(b, n, f, env); }
void shadowLookupAvx2(const ShadowPlan& plan, const ShadowView& v, const float* map, const sg::vec3& lightVec, bool positional, const ShadeBatch& b,
                      size_t i, float* out) {
    shadowLookupV(plan, v, map, lightVec, positional, b, i, out);
}
}   // namespace kern_avx2
VIEWER_ISA_REGION_END
#endif

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f, const EnvironmentLight* env) {
    if (f.settings.reflection == sg::ReflectionModel::Pbr) {
        const PbrKernelEnv e(env);
#if defined(RASTER_HAVE_AVX2)
        if (useAvx2()) {
            kern_avx2::shadePbrAvx2(b, n, f, e);
            return;
        }
#endif
        kern_sse::shadePbrKernel(b, n, f, e);
        return;
    }
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) {
        kern_avx2::shadeBatchAvx2(b, n, f);
        return;
    }
#endif
    kern_sse::shadeKernel(b, n, f);
}

size_t shadowLookupWidth() {
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) return simd_avx2::kW;
#endif
    return simd_sse::kW;
}

void shadowLookupVector(const ShadowPlan& plan, const ShadowView& v, const float* map, const sg::vec3& lightVec, bool positional, const ShadeBatch& b,
                        size_t i, float* out) {
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) {
        kern_avx2::shadowLookupAvx2(plan, v, map, lightVec, positional, b, i, out);
        return;
    }
#endif
    kern_sse::shadowLookupV(plan, v, map, lightVec, positional, b, i, out);
}

#else

size_t shadowLookupWidth() { return 0; }
void shadowLookupVector(const ShadowPlan&, const ShadowView&, const float*, const sg::vec3&, bool, const ShadeBatch&, size_t, float*) {}

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f, const EnvironmentLight* env) {
    const bool pbr = f.settings.reflection == sg::ReflectionModel::Pbr;
    for (size_t i = 0; i < n; ++i) {
        if (b.mat[i] >= 0) b.expand(i);
        if (b.kd[i] == 0 && b.ks[i] == 0) continue;
        if (pbr) {   // the layout of raster_shading.h: pbr.cpp's terms with c_diff as the albedo
            PbrPoint q;
            q.cdiffFactor = sg::vec3(1.0f);
            q.f0 = {b.sr[i], b.sg[i], b.sb[i]};
            q.f90 = b.kd[i];
            q.roughness = b.ks[i];
            q.alpha = q.roughness * q.roughness;
            const sg::vec3 p(b.px[i], b.py[i], b.pz[i]), nn(b.nx[i], b.ny[i], b.nz[i]), cdiff(b.ar[i], b.ag[i], b.ab[i]);
            sg::vec3 v = f.camera.eye - p;
            const float len = glm::length(v);
            v = len > 0 ? v / len : sg::vec3(0, 0, 1);
            sg::vec3 c(b.cr[i], b.cg[i], b.cb[i]);
            for (size_t l = 0; l < f.lights.size(); ++l) {
                const float w = b.visLights ? b.vis[l * b.visStride + i] : 1.0f;
                c += w * pbrLightTerms(q, nn, v, samplePunctualLight(f.lights[l], p)).apply(cdiff);
            }
            if (env && env->map) c += pbrEnvironmentTerms(q, nn, v, *env, b.shin[i]).apply(cdiff);
            b.cr[i] = c.x;
            b.cg[i] = c.y;
            b.cb[i] = c.z;
            continue;
        }
        sg::Material m;
        m.kd = b.kd[i];
        m.ks = b.ks[i];
        m.shininess = b.shin[i];
        m.specularColor = {b.sr[i], b.sg[i], b.sb[i]};
        SurfacePoint s{{b.px[i], b.py[i], b.pz[i]}, {b.nx[i], b.ny[i], b.nz[i]}, {b.ar[i], b.ag[i], b.ab[i]}};
        sg::vec3 v = f.camera.eye - s.position;
        float len = glm::length(v);
        v = len > 0 ? v / len : sg::vec3(0, 0, 1);
        sg::vec3 c(b.cr[i], b.cg[i], b.cb[i]);
        for (size_t l = 0; l < f.lights.size(); ++l) {
            const float w = b.visLights ? b.vis[l * b.visStride + i] : 1.0f;
            c += w * lightTerms(m, s.normal, v, sampleLight(f.lights[l], s.position), f.settings.reflection).apply(s.albedo);
        }
        b.cr[i] = c.x;
        b.cg[i] = c.y;
        b.cb[i] = c.z;
    }
}

#endif

}   // namespace rnd::raster
