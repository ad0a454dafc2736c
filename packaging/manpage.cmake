# Script mode (cmake -P): OUT = IN with the version in the .TH footer ("sceneviewer" becomes
# "sceneviewer VERSION") and the
# line '.\" @TABLE_OPTIONS@' replaced by `VIEWER --man-options`, gzipped with -9n (no name or time stamp inside, so the result only
# changes when the page does).   -DIN=docs/viewer.1 -DOUT=viewer.1.gz -DVERSION=... -DGZIP=gzip
file(READ "${IN}" page)
# The options that come from the parameter tables, as the viewer prints them (one source).
if(DEFINED VIEWER)
  # A sanitizer build's viewer runs here too: its leak report at exit is not the page's business.
  set(ENV{ASAN_OPTIONS} "detect_leaks=0")
  execute_process(COMMAND "${VIEWER}" --man-options OUTPUT_VARIABLE options RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "manpage.cmake: ${VIEWER} --man-options failed (${rc})")
  endif()
  string(REPLACE ".\\\" @TABLE_OPTIONS@\n" "${options}" page "${page}")
endif()
string(REGEX REPLACE "(\n\\.TH [^\n]*)\"sceneviewer\"" "\\1\"sceneviewer ${VERSION}\"" page "${page}")
get_filename_component(dir "${OUT}" DIRECTORY)
set(tmp "${dir}/viewer.1")
file(WRITE "${tmp}" "${page}")
execute_process(COMMAND "${GZIP}" -9 -n -c "${tmp}" OUTPUT_FILE "${OUT}.tmp" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "manpage.cmake: gzip failed (${rc})")
endif()
file(RENAME "${OUT}.tmp" "${OUT}")
file(REMOVE "${tmp}")
