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
# The Ouster capture reader (calib/io/ouster_pcap.cpp) reads pcap files through libpcap.
if(NOT TARGET PkgConfig::PCAP)
  pkg_check_modules(PCAP REQUIRED IMPORTED_TARGET libpcap)
endif()
# GigE Vision and USB3 Vision cameras (calib/capture): Aravis 0.8, whose .pc requires libusb-1.0's.
if(NOT TARGET PkgConfig::ARAVIS)
  pkg_check_modules(ARAVIS REQUIRED IMPORTED_TARGET aravis-0.8)
endif()
find_dependency(TBB)
find_dependency(apriltag)
# The image reader decodes JPEG itself and checks PNG chunk CRCs (calib/io/image_io.cpp).
find_dependency(JPEG)
find_dependency(ZLIB)
# SHA-256 of the inputs (calib/core/sha256.cpp): libcrypto, with the CPU's SHA instructions.
find_dependency(OpenSSL 3)

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

# ROS1 bags without ROS (calib/io/bag.cpp): Debian's librosbag-storage-dev. Its CMake package
# configures only with /usr/bin first on PATH and misses link libraries, and there is no
# pluginlib.pc: one imported target of our own, from the headers and libraries themselves.
if(NOT TARGET rigcal_rosbag)
  find_path(ROSBAG_INCLUDE_DIR rosbag/bag.h)
  set(ROSBAG_LIBRARIES)
  foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge boost_filesystem)
    find_library(ROSBAG_LIB_${lib} ${lib})
    if(NOT ROSBAG_LIB_${lib})
      message(FATAL_ERROR "lib${lib} not found: install Debian's librosbag-storage-dev (make deps does)")
    endif()
    list(APPEND ROSBAG_LIBRARIES ${ROSBAG_LIB_${lib}})
  endforeach()
  if(NOT ROSBAG_INCLUDE_DIR)
    message(FATAL_ERROR "rosbag/bag.h not found: install Debian's librosbag-storage-dev (make deps does)")
  endif()
  set(ROSBAG_INCLUDE_DIRS ${ROSBAG_INCLUDE_DIR})
  foreach(d pluginlib class_loader rcutils rcpputils ament_index_cpp)
    if(IS_DIRECTORY ${ROSBAG_INCLUDE_DIR}/${d})
      list(APPEND ROSBAG_INCLUDE_DIRS ${ROSBAG_INCLUDE_DIR}/${d})
    endif()
  endforeach()
  add_library(rigcal_rosbag INTERFACE IMPORTED)
  set_target_properties(rigcal_rosbag PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${ROSBAG_INCLUDE_DIRS}"
                        INTERFACE_LINK_LIBRARIES "${ROSBAG_LIBRARIES}")
endif()
