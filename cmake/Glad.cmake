# glad (python3-glad) generates the GL 4.5 core + EGL 1.5 loader at build time.
# --reproducible makes it use its bundled XML specs, so it works offline.
find_program(GLAD_EXECUTABLE glad REQUIRED)
set(GLAD_OUT ${CMAKE_BINARY_DIR}/glad)
set(GLAD_SOURCES ${GLAD_OUT}/src/gl.c ${GLAD_OUT}/src/egl.c)
add_custom_command(
  OUTPUT ${GLAD_SOURCES} ${GLAD_OUT}/include/glad/gl.h ${GLAD_OUT}/include/glad/egl.h
  COMMAND ${GLAD_EXECUTABLE} --quiet --reproducible --api "gl:core=4.5,egl=1.5"
          --extensions "GL_KHR_debug,GL_ARB_texture_filter_anisotropic,GL_MESA_pack_invert,EGL_EXT_platform_base,EGL_MESA_platform_surfaceless,EGL_KHR_surfaceless_context,EGL_KHR_no_config_context,EGL_EXT_device_base,EGL_EXT_device_enumeration,EGL_EXT_platform_device"
          --out-path ${GLAD_OUT} c --loader
  COMMENT "Generating GL/EGL loader with glad"
  VERBATIM)
add_library(glad_gl STATIC ${GLAD_SOURCES})
target_include_directories(glad_gl SYSTEM PUBLIC ${GLAD_OUT}/include)
target_link_libraries(glad_gl PUBLIC ${CMAKE_DL_LIBS})
set_target_properties(glad_gl PROPERTIES POSITION_INDEPENDENT_CODE ON)
