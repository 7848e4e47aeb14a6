# The box2d backend's layer (CMakeLists.txt includes every
# backends/*/backend.cmake): Box2D 2.4.1 behind one C++ file. Debian
# bookworm's Box2D is a C++ library found as a CMake package.
find_package(box2d CONFIG REQUIRED)
bsim_layer(box2d backends/box2d box2d::box2d)
# The version its table states is the CMake package's: Debian's 2.4.1
# still says 2.4.0 in its b2_version.
set_source_files_properties(${PROJECT_SOURCE_DIR}/backends/box2d/box2d_world.cpp PROPERTIES
                            COMPILE_DEFINITIONS BSIM_BOX2D_VERSION="${box2d_VERSION}")
# What a user of the installed package needs for it: find_dependency in
# beamsimConfig.cmake, Requires.private in beamsim.pc.
string(APPEND BSIM_PACKAGE_DEPENDENCIES "find_dependency(box2d CONFIG)\n")
list(APPEND BSIM_PC_REQUIRES box2d)
