# ctest startup_libraries: the libraries `glint` loads at every start (the dynamic loader's list,
# as ldd prints it) include none that only a preview, an MPI run, an EXR image or a mesh file
# needs: those are in modules and the mesh reader program, loaded on demand (src/CMakeLists.txt).
#   cmake -DPROGRAM=path/to/glint -P check_startup_libraries.cmake
execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_TRACE_LOADED_OBJECTS=1 ${PROGRAM}
                OUTPUT_VARIABLE loaded ERROR_VARIABLE errors RESULT_VARIABLE status)
if(NOT status EQUAL 0 OR NOT loaded MATCHES "libtbb")
  message(FATAL_ERROR "could not list the libraries of ${PROGRAM} (${status}): ${errors}${loaded}")
endif()
foreach(library IN ITEMS libcpp-httplib libssl libcrypto libmpi libopen-rte libopen-pal libhwloc
                         libOpenEXR libIex libIlmThread libassimp)
  if(loaded MATCHES "(^|[\n\t /])${library}[.-]")
    message(FATAL_ERROR "${PROGRAM} loads ${library} at every start:\n${loaded}")
  endif()
endforeach()
message(STATUS "glint starts with:\n${loaded}")
