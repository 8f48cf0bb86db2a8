# Installs the build tree into a scratch prefix and builds + runs tests/consumer against it.
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "install failed: ${rc}")
endif()
# The installed headers must all compile against the installed package (one translation unit,
# to keep the test short), and the headers of code that is not installed must not be there.
file(GLOB_RECURSE installed RELATIVE ${WORK_DIR}/prefix/include ${WORK_DIR}/prefix/include/clothcd/*.hpp)
if(NOT installed)
  message(FATAL_ERROR "no headers installed under ${WORK_DIR}/prefix/include/clothcd")
endif()
set(all_headers "")
foreach(h IN LISTS installed)
  if(h MATCHES "clothcd/experiment/|query_csv.hpp|procedural.hpp|render.hpp")
    message(FATAL_ERROR "installed a header whose code is not part of the package: ${h}")
  endif()
  string(APPEND all_headers "#include <${h}>\n")
endforeach()
file(WRITE ${WORK_DIR}/all_headers.cpp "${all_headers}")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build
                -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE}
                -DCLOTHCD_HEADER_SOURCES=${WORK_DIR}/all_headers.cpp
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build --parallel 2 RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed: ${rc}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the consumer failed: ${rc}")
endif()
