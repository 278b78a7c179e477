#!/bin/sh
# support/isa_names.sh - writes the list of function names of sections 5-9
# into the end of sph_kernel.h (the block between its "isa-names" marks): the
# run-time passes (section 1, SPH__DISPATCH) compile those sections again
# with each name mapped to name_avx2 or name_avx512. The names are read from
# the prototypes gcc writes of every function a unit defines (-aux-info),
# double and float, for each level's code (-march=x86-64, x86-64-v3,
# x86-64-v4), kept when their line lies in sections 5-9; the vector types of
# the register loops are added.
#   sh support/isa_names.sh          rewrite the block (make isa-names)
#   sh support/isa_names.sh --check  exit 1 when the block is out of date
cd "$(dirname "$0")/.." || exit 2
H=sph_kernel.h
CC=${CC:-gcc}
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
first=$(grep -n '^/\* 5\. Pair terms' $H | cut -d: -f1)
last=$(grep -n '^#endif /\* sections 5-9 \*/' $H | cut -d: -f1)
[ -n "$first" ] && [ -n "$last" ] || { echo "$0: section 5 or the end of section 9 not found in $H"; exit 2; }
printf '#include "sph_kernel.h"\n' > "$T/u.c"
for real in double float; do
    for march in x86-64 x86-64-v3 x86-64-v4; do
        $CC -std=c99 -march=$march -DSPH_NO_DISPATCH -DSPH_REAL=$real -I. -fsyntax-only -aux-info "$T/aux" "$T/u.c" ||
            exit 2
        # lines "/* path:line:NF */ static ... name (...); ...": the functions defined in sections 5-9
        awk -v f="$first" -v l="$last" '$1 == "/*" && $3 == "*/" {
            n = split($2, p, ":"); if (p[1] !~ /sph_kernel\.h$/ || p[3] !~ /F/ || p[2] + 0 < f || p[2] + 0 > l) next
            s = $0; sub(/ \(.*/, "", s); k = split(s, w, /[ *]+/); print w[k] }' "$T/aux" >> "$T/names"
    done
done
# the register loops' vector types (typedefs per level)
awk -v f="$first" -v l="$last" 'NR >= f && NR <= l && /^typedef __m/ { sub(/;.*/, ""); print $NF }' $H >> "$T/names"
sort -u "$T/names" > "$T/sorted"
[ -s "$T/sorted" ] || { echo "$0: no names found"; exit 2; }
{
    echo '/* isa-names: the names below are written by support/isa_names.sh (make isa-names) */'
    echo '#if defined(SPH__NAMES) && SPH__NAMES == 1'
    sed 's/.*/#define & SPH__LN(&)/' "$T/sorted"
    echo '#elif defined(SPH__NAMES) && SPH__NAMES == 2'
    sed 's/.*/#undef &/' "$T/sorted"
    echo '#endif'
    echo '/* isa-names end */'
} > "$T/block"
awk -v blk="$T/block" '
    /^\/\* isa-names: / { while ((getline line < blk) > 0) print line; skip = 1; next }
    /^\/\* isa-names end \*\// { skip = 0; next }
    !skip' $H > "$T/new"
grep -q '^/\* isa-names end \*/' "$T/new" || { echo "$0: the isa-names marks are missing in $H"; exit 2; }
if [ "$1" = "--check" ]; then
    if cmp -s "$T/new" $H; then echo "isa-names: up to date ($(wc -l < "$T/sorted") names)"; exit 0; fi
    echo "isa-names: the list at the end of $H is out of date: run make isa-names"
    diff $H "$T/new" | head -20
    exit 1
fi
cp "$T/new" $H && echo "isa-names: $(wc -l < "$T/sorted") names written to $H"
