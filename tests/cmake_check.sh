#!/bin/sh
# Configures and builds a tiny consumer project that does
# add_subdirectory(<this repo>) and links sph_kernel::sph_kernel.
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

# Installed package: cmake --install, then find_package(sph_kernel) from a consumer.
cmake -S "$top" -B "$dir/self" -DCMAKE_INSTALL_PREFIX="$top/$dir/prefix" > "$dir/self.log" 2>&1 || { cat "$dir/self.log"; exit 1; }
cmake --install "$dir/self" > "$dir/install.log" 2>&1 || { cat "$dir/install.log"; exit 1; }
mkdir -p "$dir/pkg"
sed -e 's|add_subdirectory.*|find_package(sph_kernel REQUIRED)|' "$dir/src/CMakeLists.txt" > "$dir/pkg/CMakeLists.txt"
cp "$dir/src/main.c" "$dir/pkg/main.c"
cmake -S "$dir/pkg" -B "$dir/pkgbuild" -DCMAKE_PREFIX_PATH="$top/$dir/prefix" > "$dir/pkg.log" 2>&1 || { cat "$dir/pkg.log"; exit 1; }
cmake --build "$dir/pkgbuild" > "$dir/pkgbuild.log" 2>&1 || { cat "$dir/pkgbuild.log"; exit 1; }
"$dir/pkgbuild/consumer"
