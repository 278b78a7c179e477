#!/bin/sh
# The CMake package: a consumer that does add_subdirectory(<this repo>) and
# links sph_kernel::sph_kernel; then the installed package (cmake --install):
# find_package(sph_kernel 0.1) finds it, find_package(sph_kernel 1.0) (another
# major version) is refused, the exported target names libm as "m" (not the
# path of this machine's libm), and the installed tree still works after it
# is moved to another prefix.
set -e
top=$(pwd)
dir=build/test/cmake_consumer
rm -rf "$dir"
mkdir -p "$dir/src"
cat > "$dir/src/CMakeLists.txt" <<CM
cmake_minimum_required(VERSION 3.10)
project(consumer C)
add_subdirectory("$top" sph_kernel_build)
add_executable(consumer main.c)
target_link_libraries(consumer PRIVATE sph_kernel::sph_kernel)
CM
cat > "$dir/src/main.c" <<C
#include <sph_kernel.h>
int main(void) { return sph_kernel_w(SPH_KERNEL_CUBIC, 3, 0.5, 1.0) > 0 ? 0 : 1; }
C
cmake -S "$dir/src" -B "$dir/build" > "$dir/cmake.log" 2>&1 || { cat "$dir/cmake.log"; exit 1; }
cmake --build "$dir/build" > "$dir/build.log" 2>&1 || { cat "$dir/build.log"; exit 1; }
"$dir/build/consumer"

# Installed package: cmake --install, then find_package(sph_kernel <version>) from a consumer.
cmake -S "$top" -B "$dir/self" -DCMAKE_INSTALL_PREFIX="$top/$dir/prefix" > "$dir/self.log" 2>&1 || { cat "$dir/self.log"; exit 1; }
cmake --install "$dir/self" > "$dir/install.log" 2>&1 || { cat "$dir/install.log"; exit 1; }
consumer() { # consumer NAME VERSION PREFIX: configure and build a find_package consumer
    mkdir -p "$dir/$1"
    sed -e "s|add_subdirectory.*|find_package(sph_kernel $2 REQUIRED)|" "$dir/src/CMakeLists.txt" > "$dir/$1/CMakeLists.txt"
    cp "$dir/src/main.c" "$dir/$1/main.c"
    cmake -S "$dir/$1" -B "$dir/$1/build" -DCMAKE_PREFIX_PATH="$3" > "$dir/$1.log" 2>&1 &&
        cmake --build "$dir/$1/build" >> "$dir/$1.log" 2>&1
}
consumer pkg 0.1 "$top/$dir/prefix" || { cat "$dir/pkg.log"; exit 1; }
"$dir/pkg/build/consumer"
if consumer pkg_major 1.0 "$top/$dir/prefix"; then
    echo "find_package(sph_kernel 1.0) accepted version 0.x"
    exit 1
fi
grep -q 'version: 0.1' "$dir/pkg_major.log" || { cat "$dir/pkg_major.log"; exit 1; } # refused for its version, not missing
# libm by name in the exported target, no absolute library path
config="$dir/prefix/lib/cmake/sph_kernel/sph_kernelConfig.cmake"
grep -q 'INTERFACE_LINK_LIBRARIES "m"' "$config" || { echo "libm not linked as \"m\":"; grep LINK "$config"; exit 1; }
if grep -n "/lib[^ ]*libm\." "$config"; then echo "absolute libm path in $config"; exit 1; fi
# relocatable: the same tree under another prefix
mv "$dir/prefix" "$dir/moved"
consumer pkg_moved 0.1 "$top/$dir/moved" || { cat "$dir/pkg_moved.log"; exit 1; }
"$dir/pkg_moved/build/consumer"
