# Every third-party dependency of igi, found through its own CMake package or pkg-config,
# as Debian 12 ships it. Each is exposed as an imported target; nothing is vendored.
find_package(PkgConfig REQUIRED)

find_package(Eigen3 3.4 REQUIRED NO_MODULE)                 # Eigen3::Eigen
find_package(nlohmann_json 3.10 REQUIRED)                   # nlohmann_json::nlohmann_json
find_package(fmt REQUIRED)                                  # fmt::fmt
find_package(spdlog REQUIRED)                               # spdlog::spdlog
find_package(CLI11 CONFIG REQUIRED)                         # CLI11::CLI11
find_package(TBB REQUIRED)                                  # TBB::tbb
find_package(OpenImageIO REQUIRED)                          # OpenImageIO::OpenImageIO
find_package(OpenEXR 3 REQUIRED)                            # OpenEXR::OpenEXR
find_package(assimp REQUIRED)                               # assimp::assimp
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d photo features2d
  aruco)                                                    # aruco: libopencv-contrib-dev
find_package(Ceres 2 REQUIRED)                              # Ceres::ceres
find_package(embree 3 REQUIRED)                             # embree
pkg_check_modules(LIBRAW REQUIRED IMPORTED_TARGET libraw_r)  # PkgConfig::LIBRAW
pkg_check_modules(ARAVIS REQUIRED IMPORTED_TARGET aravis-0.8)  # PkgConfig::ARAVIS
pkg_check_modules(LIBUSB REQUIRED IMPORTED_TARGET libusb-1.0)  # Aravis's USB3 side

# OpenCV's config gives plain target names; gather them into one interface target.
add_library(igi_opencv INTERFACE)
target_link_libraries(igi_opencv INTERFACE ${OpenCV_LIBS})
target_include_directories(igi_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})

if(IGI_BUILD_TESTS)
  find_package(GTest REQUIRED)                              # GTest::gtest, GTest::gtest_main
endif()
