// tile_kernels.cpp - tile_kernels.h's functions: tile_kernels.inl compiled for SSE2 and for AVX2,
// chosen at run time by useAvx2() (simd.h).
#include "raster/tile_kernels.h"

#include "raster/simd.h"

#include <algorithm>

namespace rnd::raster {

#if defined(RASTER_HAVE_SSE2)
namespace tile_sse {
using namespace simd_sse;
#include "raster/tile_kernels.inl"
}   // namespace tile_sse

#if defined(RASTER_HAVE_AVX2)
VIEWER_ISA_REGION_BEGIN("avx2")
namespace tile_avx2 {
using namespace simd_avx2;
#include "raster/tile_kernels.inl"
void rasterizeOpaqueAvx2(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0, int x0, int y0, int x1, int y1, float* depth,
                         uint32_t* ids) {
    rasterizeOpaqueKernel(s, pl, id, tx0, ty0, x0, y0, x1, y1, depth, ids);
}
void preparePlainRunAvx2(const PlainTri& t, bool fog, const uint16_t* fragPixel, int x0, int y0, size_t k, size_t count, const BatchOut& o,
                         float* fogDist) {
    preparePlainKernel(t, fog, fragPixel, x0, y0, k, count, o, fogDist);
}
void writeFragmentsAvx2(const float* cr, const float* cg, const float* cb, const float* fogDist, const uint16_t* fragPixel, size_t n,
                        const LinearFog& fog, const SrgbEncoder& srgb, uint32_t* color) {
    writeFragmentsKernel(cr, cg, cb, fogDist, fragPixel, n, fog, srgb, color);
}
}   // namespace tile_avx2
VIEWER_ISA_REGION_END
#endif

void rasterizeOpaque(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0, int x0, int y0, int x1, int y1, float* depth,
                     uint32_t* ids) {
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) return tile_avx2::rasterizeOpaqueAvx2(s, pl, id, tx0, ty0, x0, y0, x1, y1, depth, ids);
#endif
    tile_sse::rasterizeOpaqueKernel(s, pl, id, tx0, ty0, x0, y0, x1, y1, depth, ids);
}

void preparePlainRun(const PlainTri& t, bool fog, const uint16_t* fragPixel, int x0, int y0, size_t k, size_t count, const BatchOut& o,
                     float* fogDist) {
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) return tile_avx2::preparePlainRunAvx2(t, fog, fragPixel, x0, y0, k, count, o, fogDist);
#endif
    tile_sse::preparePlainKernel(t, fog, fragPixel, x0, y0, k, count, o, fogDist);
}

void writeFragments(const float* cr, const float* cg, const float* cb, const float* fogDist, const uint16_t* fragPixel, size_t n,
                    const LinearFog& fog, const SrgbEncoder& srgb, uint32_t* color) {
#if defined(RASTER_HAVE_AVX2)
    if (useAvx2()) return tile_avx2::writeFragmentsAvx2(cr, cg, cb, fogDist, fragPixel, n, fog, srgb, color);
#endif
    tile_sse::writeFragmentsKernel(cr, cg, cb, fogDist, fragPixel, n, fog, srgb, color);
}

#endif   // without SSE2 (not x86-64) the renderer keeps to its scalar loops

}   // namespace rnd::raster
