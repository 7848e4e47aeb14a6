# The thesis backend's layer (CMakeLists.txt includes every
# backends/*/backend.cmake): the essay's solver, C, with OpenMP for its
# parallel beam updates.
bsim_layer(thesis backends/thesis OpenMP::OpenMP_C m)
