#!/bin/sh
# The installed and the embedded package, by both routes:
# - add_subdirectory(<this repo>) from a C project and from a C++-only one
#   (project(... LANGUAGES CXX): the library must not make it enable C);
# - cmake --install: find_package(sph_kernel 0.1) finds it from C and C++,
#   find_package(sph_kernel 1.0) is refused, and so is 0.1 by a package of
#   version 1.0 (SameMajorVersion), libm is
#   named "m" (not this machine's path), pkg-config sph_kernel works, and
#   the tree still works after it is moved to another prefix;
# - make install PREFIX=...: the same find_package and pkg-config, a program
#   built with pkg-config's flags; make install DESTDIR=... installs the same
#   files under DESTDIR; make uninstall leaves nothing behind.
set -e
top=$(pwd)
dir=build/test/cmake_consumer
rm -rf "$dir"
mkdir -p "$dir/src" "$dir/srcxx"
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
sed -e 's/project(consumer C)/project(consumer LANGUAGES CXX)/' -e 's/main\.c/main.cpp/' \
    "$dir/src/CMakeLists.txt" > "$dir/srcxx/CMakeLists.txt"
cp "$dir/src/main.c" "$dir/srcxx/main.cpp"

configure_build() { # configure_build NAME SOURCE-DIR [cmake options]: configure and build into dir/NAME
    name=$1 src=$2
    shift 2
    cmake -S "$src" -B "$dir/$name" "$@" > "$dir/$name.log" 2>&1 && cmake --build "$dir/$name" >> "$dir/$name.log" 2>&1
}
built() { # built NAME SOURCE-DIR [cmake options]: configure_build, and the program runs
    configure_build "$@" || { cat "$dir/$1.log"; exit 1; }
    "$dir/$1/consumer" || { echo "$1: the consumer failed"; exit 1; }
}
built sub_c "$dir/src"
built sub_cxx "$dir/srcxx"
if grep -q 'The C compiler identification' "$dir/sub_cxx.log"; then
    echo "a C++-only project that adds sph_kernel had C enabled:"; cat "$dir/sub_cxx.log"; exit 1
fi

# find_package consumers (C and C++) of the sources above
for lang in src srcxx; do
    mkdir -p "$dir/find_$lang"
    sed -e "s|add_subdirectory.*|find_package(sph_kernel \${WANT} REQUIRED)|" "$dir/$lang/CMakeLists.txt" > "$dir/find_$lang/CMakeLists.txt"
    cp "$dir/$lang"/main.* "$dir/find_$lang/"
done
found() { # found PREFIX TAG: find_package(sph_kernel 0.1) from C and C++ builds; 1.0 is refused
    built "$2_c" "$dir/find_src" -DWANT=0.1 -DCMAKE_PREFIX_PATH="$1"
    built "$2_cxx" "$dir/find_srcxx" -DWANT=0.1 -DCMAKE_PREFIX_PATH="$1"
    if configure_build "$2_major" "$dir/find_src" -DWANT=1.0 -DCMAKE_PREFIX_PATH="$1"; then
        echo "$2: find_package(sph_kernel 1.0) accepted version 0.x"; exit 1
    fi
    grep -q 'version: 0\.' "$dir/$2_major.log" || { cat "$dir/$2_major.log"; exit 1; } # refused for its version, not missing
}
# shellcheck disable=SC2086,SC2116 # echo $cflags drops pkg-config's trailing blank
pkgconfig() { # pkgconfig PREFIX: pkg-config finds sph_kernel there and a program builds with its flags
    flags=$(PKG_CONFIG_PATH="$1/lib/pkgconfig" pkg-config --cflags --libs sph_kernel) || { echo "pkg-config: no sph_kernel in $1"; exit 1; }
    cflags=$(PKG_CONFIG_PATH="$1/lib/pkgconfig" pkg-config --cflags sph_kernel)
    [ "$(echo $cflags)" = "-I$1/include" ] || { echo "pkg-config --cflags sph_kernel: $cflags, expected -I$1/include"; exit 1; }
    # shellcheck disable=SC2086 # the flags are words
    cc -std=c99 "$dir/src/main.c" -o "$dir/pc_consumer" $flags && "$dir/pc_consumer"
}
have_pkgconfig=0
if command -v pkg-config > /dev/null 2>&1; then have_pkgconfig=1; else echo "SKIPPED: the pkg-config checks (pkg-config is not installed)"; fi

# cmake --install
configure_build self "$top" -DCMAKE_INSTALL_PREFIX="$top/$dir/prefix" || { cat "$dir/self.log"; exit 1; }
cmake --install "$dir/self" > "$dir/install.log" 2>&1 || { cat "$dir/install.log"; exit 1; }
found "$top/$dir/prefix" cm
[ "$have_pkgconfig" = 0 ] || pkgconfig "$top/$dir/prefix"
config="$dir/prefix/lib/cmake/sph_kernel/sph_kernelConfig.cmake"
grep -q 'INTERFACE_LINK_LIBRARIES "m"' "$config" || { echo "libm not linked as \"m\":"; grep LINK "$config"; exit 1; }
if grep -n "/lib[^ ]*libm\." "$config"; then echo "absolute libm path in $config"; exit 1; fi
mv "$dir/prefix" "$dir/moved" # relocatable: the same tree under another prefix
built cm_moved "$dir/find_srcxx" -DWANT=0.1 -DCMAKE_PREFIX_PATH="$top/$dir/moved"
# the major rule from the other side: a package of version 1.0 does not serve 0.1
vfile=$dir/moved/lib/cmake/sph_kernel/sph_kernelConfigVersion.cmake
sed 's/^set(PACKAGE_VERSION ".*")$/set(PACKAGE_VERSION "1.0")/' "$vfile" > "$dir/v1" && cp "$vfile" "$dir/v0" && cp "$dir/v1" "$vfile"
if configure_build cm_v1 "$dir/find_src" -DWANT=0.1 -DCMAKE_PREFIX_PATH="$top/$dir/moved"; then
    echo "find_package(sph_kernel 0.1) accepted version 1.0"; exit 1
fi
cp "$dir/v0" "$vfile"

# make install: the same files, the same package
make -s --no-print-directory install PREFIX="$top/$dir/mk" > "$dir/mk.log" 2>&1 || { cat "$dir/mk.log"; exit 1; }
(cd "$dir/mk" && find . -type f | sort) > "$dir/mk.files"
(cd "$dir/moved" && find . -type f | sort) > "$dir/cm.files"
diff "$dir/cm.files" "$dir/mk.files" || { echo "make install and cmake --install install different files"; exit 1; }
found "$top/$dir/mk" mk
[ "$have_pkgconfig" = 0 ] || pkgconfig "$top/$dir/mk"
make -s --no-print-directory install DESTDIR="$top/$dir/stage" PREFIX=/opt/sph > "$dir/stage.log" 2>&1 || { cat "$dir/stage.log"; exit 1; }
(cd "$dir/stage/opt/sph" && find . -type f | sort) | diff "$dir/mk.files" - || { echo "make install DESTDIR= installed other files"; exit 1; }
grep -q '^prefix=/opt/sph$' "$dir/stage/opt/sph/lib/pkgconfig/sph_kernel.pc" || { echo "DESTDIR in the installed pkg-config file"; exit 1; }
for d in "PREFIX=$top/$dir/mk" "DESTDIR=$top/$dir/stage PREFIX=/opt/sph"; do
    # shellcheck disable=SC2086 # d is words
    make -s --no-print-directory uninstall $d > /dev/null 2>&1
done
left=$(find "$dir/mk" "$dir/stage" -type f)
[ -z "$left" ] || { echo "make uninstall left:"; echo "$left"; exit 1; }
[ ! -d "$dir/mk/lib/cmake/sph_kernel" ] || { echo "make uninstall left lib/cmake/sph_kernel"; exit 1; }
echo "cmake_check: add_subdirectory (C, C++), cmake --install and make install (find_package, pkg-config), make uninstall: ok"
