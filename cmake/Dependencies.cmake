# Every third-party library gilt uses, all from Debian 12 packages (see scripts/install-deps.sh).

find_package(Threads REQUIRED)
find_package(glm CONFIG REQUIRED)
find_package(embree 3 CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(tinyobjloader CONFIG REQUIRED)
# tinygltf: the header from libtinygltf-dev, with the implementation compiled by gilt itself
# (raytrace_core/io/tinygltf_impl.cpp), not Debian's libtinygltf, which is built without Draco.
# That implementation decodes KHR_draco_mesh_compression primitives with libdraco and keeps
# tinygltf's default image reader and writer, whose stb_image code comes from libstb (headers in
# libstb-dev, under stb/).
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_package(draco CONFIG REQUIRED)
find_path(STB_INCLUDE_DIR stb/stb_image.h REQUIRED)
find_library(STB_LIBRARY stb REQUIRED)

# OpenImageIO: Debian's exported CMake targets check for files the -dev package does not bring
# (the command-line tools in openimageio-tools, which pull Qt, and Imath's Python bindings), and
# they list /usr/include/opencv4 as an include directory. The package's pkg-config file has none
# of these problems, so gilt links OpenImageIO through it.
find_package(PkgConfig REQUIRED)
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET GLOBAL OpenImageIO)
add_library(OpenImageIO::OpenImageIO ALIAS PkgConfig::OIIO)

# OpenMesh: CGAL ships a FindOpenMesh.cmake that fails on Debian; ask for the package's own config.
find_package(OpenMesh CONFIG REQUIRED)
find_package(CGAL CONFIG REQUIRED)
# Eigen: sparse conjugate gradients for the least-squares vertex fit (radiosity/bake/vertex_fit.cpp).
find_package(Eigen3 3.3 CONFIG REQUIRED NO_MODULE)

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

# MPI for `mpirun -np N gilt render` (GILT_MPI): Debian's Open MPI (libopenmpi-dev, openmpi-bin).
if(GILT_MPI)
  find_package(MPI REQUIRED COMPONENTS CXX)
endif()
