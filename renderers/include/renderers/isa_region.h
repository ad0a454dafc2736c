// isa_region.h - open and close a region of code compiled for a wider instruction set than the
// build's baseline (x86-64), for kernels chosen at run time by a CPU check. GCC takes
// `#pragma GCC target`; clang ignores that pragma and needs a target attribute on every function
// of the region instead (`#pragma clang attribute`). Both spellings sit behind one pair of macros so
// every compiler the project uses (GCC for the product, clang for the fuzz targets) builds the same
// kernels:
//
//     VIEWER_ISA_REGION_BEGIN("avx2")
//     namespace kern_avx2 { ... }
//     VIEWER_ISA_REGION_END
#pragma once

#define VIEWER_ISA_PRAGMA(x) _Pragma(#x)

#if defined(__clang__)
#define VIEWER_ISA_REGION_BEGIN(isa) VIEWER_ISA_PRAGMA(clang attribute push(__attribute__((target(isa))), apply_to = function))
#define VIEWER_ISA_REGION_END VIEWER_ISA_PRAGMA(clang attribute pop)
#else
#define VIEWER_ISA_REGION_BEGIN(isa) VIEWER_ISA_PRAGMA(GCC push_options) VIEWER_ISA_PRAGMA(GCC target(isa))
#define VIEWER_ISA_REGION_END VIEWER_ISA_PRAGMA(GCC pop_options)
#endif
