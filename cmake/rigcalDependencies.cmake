# Third-party packages of the rigcal library. Used by the build and, installed, by rigcalConfig.cmake,
# so a downstream project gets the same imported targets. All come from Debian 12 packages
# (scripts/debian-packages.txt).
include(CMakeFindDependencyMacro)
find_dependency(Eigen3 3.4 NO_MODULE)
find_dependency(yaml-cpp)
find_dependency(fmt)
find_dependency(nlohmann_json 3)
find_dependency(OpenCV 4 COMPONENTS core calib3d imgproc imgcodecs aruco)
find_dependency(Ceres 2.1)
find_dependency(PkgConfig)
if(NOT TARGET PkgConfig::GEOGRAPHICLIB)
  pkg_check_modules(GEOGRAPHICLIB REQUIRED IMPORTED_TARGET geographiclib)
endif()
if(NOT TARGET PkgConfig::CAIRO)
  pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo cairo-pdf)
endif()
find_dependency(TBB)
find_dependency(apriltag)
# The image reader decodes JPEG itself and checks PNG chunk CRCs (calib/io/image_io.cpp).
find_dependency(JPEG)
find_dependency(ZLIB)

# mrcal 2.2 ships no CMake or pkg-config file: one header folder and -lmrcal.
if(NOT TARGET rigcal_mrcal)
  find_path(MRCAL_INCLUDE_DIR mrcal/mrcal.h)
  find_library(MRCAL_LIBRARY mrcal)
  if(NOT MRCAL_INCLUDE_DIR OR NOT MRCAL_LIBRARY)
    message(FATAL_ERROR "mrcal not found: install Debian's libmrcal-dev (make deps does)")
  endif()
  add_library(rigcal_mrcal UNKNOWN IMPORTED)
  set_target_properties(rigcal_mrcal PROPERTIES IMPORTED_LOCATION ${MRCAL_LIBRARY}
                        INTERFACE_INCLUDE_DIRECTORIES ${MRCAL_INCLUDE_DIR})
endif()
