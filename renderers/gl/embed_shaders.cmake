# Writes OUT: a C++ file defining one `const char* const` per shader file in FILES, named
# kShader_<file name with . replaced by _>, holding the file's text verbatim.
string(REPLACE "|" ";" FILES "${FILES}")
set(code "// Generated from renderers/gl/shaders by embed_shaders.cmake: do not edit.\nnamespace rnd::gl {\n")
foreach(f ${FILES})
  get_filename_component(name ${f} NAME)
  string(REPLACE "." "_" name ${name})
  file(READ ${f} text)
  string(APPEND code "extern const char* const kShader_${name};\nconst char* const kShader_${name} = R\"GLSL(${text})GLSL\";\n")
endforeach()
string(APPEND code "}  // namespace rnd::gl\n")
file(WRITE ${OUT}.tmp "${code}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
