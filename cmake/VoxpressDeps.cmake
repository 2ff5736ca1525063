# Dependencies: system packages first (Debian 12), clear message otherwise.
# scripts/setup.sh installs every package named here.
function(voxpress_require pkg debian)
  find_package(${pkg} ${ARGN} QUIET)
  if(NOT ${pkg}_FOUND)
    message(FATAL_ERROR "voxpress needs ${pkg}: install it with `apt-get install ${debian}` "
                        "(scripts/setup.sh installs everything).")
  endif()
endfunction()

voxpress_require(Eigen3 libeigen3-dev 3.3 NO_MODULE)
voxpress_require(TBB libtbb-dev)
voxpress_require(ZLIB zlib1g-dev)
voxpress_require(TIFF libtiff-dev)
voxpress_require(PNG libpng-dev)
# Debian 12's NIFTIConfig.cmake points at /usr/lib/libznz.so.3.0.0, which the
# package does not ship; locate nifti_clib directly instead.
find_path(NIFTI_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti)
find_library(NIFTI2_LIBRARY nifti2)
find_library(ZNZ_LIBRARY znz)
if(NOT NIFTI_INCLUDE_DIR OR NOT NIFTI2_LIBRARY OR NOT ZNZ_LIBRARY)
  message(FATAL_ERROR "voxpress needs nifti_clib: install it with `apt-get install libnifti2-dev`.")
endif()
add_library(voxpress_nifti INTERFACE)
target_include_directories(voxpress_nifti SYSTEM INTERFACE ${NIFTI_INCLUDE_DIR})
target_link_libraries(voxpress_nifti INTERFACE ${NIFTI2_LIBRARY} ${ZNZ_LIBRARY} ZLIB::ZLIB m)
voxpress_require(HDF5 libhdf5-dev COMPONENTS C)
voxpress_require(TinyGLTF libtinygltf-dev)
voxpress_require(tinyobjloader libtinyobjloader-dev)
voxpress_require(nlohmann_json nlohmann-json3-dev)

voxpress_require(CLI11 libcli11-dev)
voxpress_require(meshoptimizer libmeshoptimizer-dev CONFIG)
if(VOXPRESS_BUILD_TESTS OR VOXPRESS_FUZZ)
  voxpress_require(GTest libgtest-dev)
endif()
if(VOXPRESS_BUILD_BENCH)
  voxpress_require(benchmark libbenchmark-dev)
endif()
