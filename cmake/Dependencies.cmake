# Every third-party library gilt uses, all from Debian 12 packages (see scripts/install-deps.sh).

find_package(Threads REQUIRED)
find_package(glm CONFIG REQUIRED)
find_package(embree 3 CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(tinyobjloader CONFIG REQUIRED)
find_package(TinyGLTF CONFIG REQUIRED)

# OpenImageIO's exported target names /usr/include/opencv4 as an include directory even when
# OpenCV is not installed, which fails CMake's generate step. Drop that entry.
find_package(OpenImageIO CONFIG REQUIRED)
foreach(_oiio_target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_oiio_target})
    get_target_property(_dirs ${_oiio_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(_dirs)
      list(FILTER _dirs EXCLUDE REGEX "opencv")
      set_target_properties(${_oiio_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_dirs}")
    endif()
  endif()
endforeach()

# OpenMesh: CGAL ships a FindOpenMesh.cmake that fails on Debian; ask for the package's own config.
find_package(OpenMesh CONFIG REQUIRED)
find_package(CGAL CONFIG REQUIRED)

# FLANN's kd-tree is header-only. Its CMake target would link a static library into every binary,
# so take the include directory only, plus liblz4 which its serialisation headers use.
find_path(FLANN_INCLUDE_DIR flann/flann.hpp REQUIRED)
find_library(LZ4_LIBRARY lz4 REQUIRED)
add_library(gilt_flann INTERFACE)
target_include_directories(gilt_flann SYSTEM INTERFACE ${FLANN_INCLUDE_DIR})
target_link_libraries(gilt_flann INTERFACE ${LZ4_LIBRARY})
add_library(gilt::flann ALIAS gilt_flann)

if(GILT_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(GILT_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()
