# Each folder of src/ is a module: an OBJECT library `clothcd_<name>` that lists the modules it may
# use. The installed `clothcd` library is the union of all modules' objects; tests link only the
# modules they exercise, so one module builds and tests while another is being edited.
set_property(GLOBAL PROPERTY CLOTHCD_MODULES "")

function(clothcd_module name)
  cmake_parse_arguments(ARG "STANDALONE" "" "SOURCES;USES;LIBS" ${ARGN})
  set(target clothcd_${name})
  add_library(${target} OBJECT ${ARG_SOURCES})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include> $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>)
  set(uses "")
  foreach(dep IN LISTS ARG_USES)
    list(APPEND uses clothcd_${dep})
  endforeach()
  target_link_libraries(${target} PUBLIC clothcd_flags ${uses} ${ARG_LIBS})
  if(BUILD_SHARED_LIBS)
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
  # STANDALONE modules (the simulator) are not part of the `clothcd` library.
  if(NOT ARG_STANDALONE)
    set_property(GLOBAL APPEND PROPERTY CLOTHCD_MODULES ${name})
  endif()
  set_property(TARGET ${target} PROPERTY CLOTHCD_USES ${ARG_USES})
endfunction()

# The objects of a module and of every module it uses, transitively (object files do not propagate
# through target_link_libraries).
function(clothcd_module_closure out)
  set(todo ${ARGN})
  set(done "")
  while(todo)
    list(POP_FRONT todo m)
    if(m IN_LIST done)
      continue()
    endif()
    list(APPEND done ${m})
    get_target_property(deps clothcd_${m} CLOTHCD_USES)
    if(deps)
      list(APPEND todo ${deps})
    endif()
  endwhile()
  set(${out} ${done} PARENT_SCOPE)
endfunction()

# Links the objects of the named modules (and what they use) into `target`: linking an OBJECT
# library directly adds its object files.
function(clothcd_link_modules target)
  clothcd_module_closure(mods ${ARGN})
  foreach(m IN LISTS mods)
    target_link_libraries(${target} PRIVATE clothcd_${m})
  endforeach()
endfunction()
