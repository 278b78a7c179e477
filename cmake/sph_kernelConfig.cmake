# The installed sph_kernel.h as the INTERFACE target sph_kernel::sph_kernel
# (find_package(sph_kernel 0.1)). make install and cmake --install both
# install this file as written: the include directory is found from where
# the file lies (<prefix>/lib/cmake/sph_kernel), so the prefix can be moved,
# and libm is named "m", not by a path of the machine that installed it.
get_filename_component(_sph_kernel_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)
if(NOT TARGET sph_kernel::sph_kernel)
    add_library(sph_kernel::sph_kernel INTERFACE IMPORTED)
    set_target_properties(sph_kernel::sph_kernel PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${_sph_kernel_prefix}/include")
    if(NOT WIN32) # the C library of Windows has the maths functions and no libm
        set_target_properties(sph_kernel::sph_kernel PROPERTIES INTERFACE_LINK_LIBRARIES "m")
    endif()
endif()
unset(_sph_kernel_prefix)
