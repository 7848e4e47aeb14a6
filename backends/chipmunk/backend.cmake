# The chipmunk backend's layer (CMakeLists.txt includes every
# backends/*/backend.cmake): Chipmunk2D 7, C. Debian's libchipmunk-dev ships
# neither a CMake package nor a pkg-config file: its header and library, as
# one imported target. The version its table states is the library's own
# (cpVersionString).
find_path(CHIPMUNK_INCLUDE_DIR chipmunk/chipmunk.h REQUIRED)
find_library(CHIPMUNK_LIBRARY chipmunk REQUIRED)
add_library(chipmunk::chipmunk UNKNOWN IMPORTED)
set_target_properties(chipmunk::chipmunk PROPERTIES IMPORTED_LOCATION ${CHIPMUNK_LIBRARY}
                      INTERFACE_INCLUDE_DIRECTORIES ${CHIPMUNK_INCLUDE_DIR})
bsim_layer(chipmunk backends/chipmunk chipmunk::chipmunk m)
# What a user of the installed package needs for it: the same imported
# target in beamsimConfig.cmake; -lchipmunk in beamsim.pc's Libs.private,
# there being no pkg-config name to require.
string(APPEND BSIM_PACKAGE_DEPENDENCIES
       "find_path(CHIPMUNK_INCLUDE_DIR chipmunk/chipmunk.h REQUIRED)\n"
       "find_library(CHIPMUNK_LIBRARY chipmunk REQUIRED)\n"
       "if(NOT TARGET chipmunk::chipmunk)\n"
       "  add_library(chipmunk::chipmunk UNKNOWN IMPORTED)\n"
       "  set_target_properties(chipmunk::chipmunk PROPERTIES IMPORTED_LOCATION \${CHIPMUNK_LIBRARY}\n"
       "                        INTERFACE_INCLUDE_DIRECTORIES \${CHIPMUNK_INCLUDE_DIR})\n"
       "endif()\n")
list(APPEND BSIM_PC_LIBS_PRIVATE -lchipmunk)
