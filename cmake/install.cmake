# Installation and packaging (DESIGN.md §14). `cmake --install build [--prefix P]` puts in place:
#   bin/glint                                the command            (component runtime)
#   libexec/glint/glint-mesh-reader          reads mesh files for glint and the library (runtime)
#   libexec/glint/glint-*.so                 modules loaded on demand: the preview's HTTP server,
#                                            OpenEXR (runtime), the MPI transport (component mpi)
#   lib/libglint.a, include/glint/           the library, headers   (component dev)
#   lib/cmake/glint/                         find_package(glint CONFIG) -> glint::glint (dev)
# `cpack --config build/CPackConfig.cmake` makes the .debs: glint (the command; its Depends from
# dpkg-shlibdeps), glint-mpi (the MPI module, with MPI builds) and libglint-dev (library, headers,
# package; Depends on the -dev packages that glintConfig.cmake finds, and on glint for the same
# version).
include(CMakePackageConfigHelpers)

install(TARGETS glint_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(TARGETS glint_mesh_reader RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/glint
        COMPONENT runtime)
install(TARGETS glint_preview_http glint_exr LIBRARY DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/glint
        COMPONENT runtime)
# Its own component (and .deb, glint-mpi): OpenMPI is large, and only `mpirun glint` loads it.
if(TARGET glint_mpi)
  install(TARGETS glint_mpi LIBRARY DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/glint
          COMPONENT mpi)
endif()
install(TARGETS glint EXPORT glintTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
# Every library header (glint/glint.h includes the public API); not the command's, not tests'.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/glint/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glint
        COMPONENT dev FILES_MATCHING PATTERN "*.h"
        PATTERN "*_test_support.h" EXCLUDE PATTERN "cli" EXCLUDE
        # The mesh reader's side of the import (glint_mesh_import, not in libglint).
        PATTERN "assimp_import.h" EXCLUDE PATTERN "obj_fast_parse.h" EXCLUDE
        PATTERN "mesh_reader_side.h" EXCLUDE PATTERN "mesh_reader_wire.h" EXCLUDE
        PATTERN "cluster" EXCLUDE)  # built only with MPI, into the command alone
install(FILES ${PROJECT_BINARY_DIR}/include/glint/core/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glint/core COMPONENT dev)

set(GLINT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/glint)
install(EXPORT glintTargets NAMESPACE glint:: DESTINATION ${GLINT_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/glintConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/glintConfig.cmake
                              INSTALL_DESTINATION ${GLINT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/glintConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/glintConfig.cmake ${PROJECT_BINARY_DIR}/glintConfigVersion.cmake
        DESTINATION ${GLINT_CMAKE_DIR} COMPONENT dev)

set(CPACK_PACKAGE_NAME glint)
set(CPACK_PACKAGE_VENDOR "glint")
set(CPACK_PACKAGE_CONTACT "glint maintainers <glint@localhost>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX ${GLINT_PACKAGE_PREFIX})
set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
if(TARGET glint_mpi)
  set(CPACK_COMPONENTS_ALL runtime mpi dev)
else()
  set(CPACK_COMPONENTS_ALL runtime dev)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME glint)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
# Each description: the summary line, then the long text (one string: a CMake list would show ';').
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "fast, exact Whitted ray tracer for YAML scene files
Renders scenes of shapes, triangle meshes (OBJ, PLY, STL, glTF), lights and materials to PNG, PPM
or OpenEXR on every core, with a live preview in the browser.")
# One frame across MPI ranks (docs/distributed.md): the module alone, its Depends from
# dpkg-shlibdeps (OpenMPI), offered by glint rather than required.
set(CPACK_DEBIAN_MPI_PACKAGE_NAME glint-mpi)
set(CPACK_DEBIAN_MPI_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_MPI_PACKAGE_DEPENDS "glint (= ${PROJECT_VERSION})")
set(CPACK_DEBIAN_MPI_DESCRIPTION "glint ray tracer: one frame across OpenMPI ranks
The module glint loads when started by mpirun: tiles rendered on every rank, one image.")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "glint-mpi")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME libglint-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION "glint ray tracer: static library, headers and CMake package
find_package(glint CONFIG) gives the target glint::glint.")
# What glintConfig.cmake finds (find_dependency, pkg-config), as Debian packages.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "glint (= ${PROJECT_VERSION}), cmake, pkg-config, libtbb-dev, libfmt-dev, libpng-dev, \
libjpeg62-turbo-dev, libyaml-dev")
include(CPack)
