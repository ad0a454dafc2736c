# Flags attached through an INTERFACE target instead of global CMAKE_CXX_FLAGS.
add_library(viewer_options INTERFACE)
target_compile_options(viewer_options INTERFACE -Wall -Wextra $<$<COMPILE_LANGUAGE:CXX>:-Wno-missing-field-initializers>)
# GCC 12 reports -Wrestrict false positives inside libstdc++'s std::string (GCC bug 105329).
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(viewer_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Wno-restrict>)
endif()
# The release preset (./test, CI) builds warning-free. The sanitizer build is not held to it:
# GCC 12 reports -Wmaybe-uninitialized false positives inside std::variant under ASan.
if(VIEWER_WERROR)
  target_compile_options(viewer_options INTERFACE -Werror)
endif()
if(VIEWER_NATIVE)
  # No fused multiply-adds the code does not ask for: the vector kernels that stand for scalar
  # code (the ray caster's lane shading, the rasterizer's SSE2/AVX2 kernels) give its bits only
  # when neither side is contracted.
  target_compile_options(viewer_options INTERFACE -march=native -ffp-contract=off)
endif()
if(VIEWER_SANITIZE)
  target_compile_options(viewer_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(viewer_options INTERFACE -fsanitize=address,undefined)
endif()
if(VIEWER_TSAN)
  # ThreadSanitizer (the tsan preset). It only means something with a TBB built with it too
  # (scripts/build-tbb-tsan.sh; the preset points TBB_DIR there): Debian's libtbb is not
  # instrumented, so TSan cannot see its synchronisation and reports races inside its scheduler.
  target_compile_options(viewer_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(viewer_options INTERFACE -fsanitize=thread)
endif()
if(VIEWER_FUZZ)
  # Coverage instrumentation for libFuzzer on all our code; the fuzz targets add -fsanitize=fuzzer.
  target_compile_options(viewer_options INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -gline-tables-only)
  target_link_options(viewer_options INTERFACE -fsanitize=address,undefined)
endif()
