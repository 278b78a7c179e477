#!/bin/sh
# tests/check_doc_snippets.sh - code shown in the Markdown pages is the code
# that make test compiles and runs. A page shows a region of a program as
#
#   <!-- snippet: examples/smoothing_length_quickstart.c adaptive_h -->
#   ```c
#   ...the lines...
#   ```
#
# and the program marks the region with a line `/* snippet: adaptive_h */`
# before it and `/* end snippet */` after it. The block must equal the
# region's lines with their common indentation removed. A page shows what a
# program prints (a table) as
#
#   <!-- output: examples/kernel_table.c --eta -->
#   ...the lines...
#   <!-- end output -->
#
# and the lines must be what the program, built here (gcc -O0 -std=c99,
# this tree's header) and run with the marker's arguments, prints. Fails
# (exit 1, naming page, line and the first differing lines) on a block that
# differs, a marker whose file or region does not exist, a program that
# does not build, a region no page shows, and when no snippet is found at
# all.
cd "$(dirname "$0")/.." || exit 2
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
bad=0
checked=0
outputs=0

region() { # region file name: the lines between the markers, dedented
    awk -v name="$2" '
        $0 ~ "^[ \t]*/\\* snippet: " name " \\*/[ \t]*$" { on = 1; found = 1; next }
        on && /^[ \t]*\/\* end snippet \*\/[ \t]*$/ { exit }
        on { line[++n] = $0 }
        END {
            if (!found) exit 3
            min = -1
            for (i = 1; i <= n; ++i) {
                if (line[i] ~ /^[ \t]*$/) continue
                match(line[i], /^ */)
                if (min < 0 || RLENGTH < min) min = RLENGTH
            }
            for (i = 1; i <= n; ++i) print (line[i] ~ /^[ \t]*$/ ? "" : substr(line[i], min + 1))
        }' "$1"
}

same() { # same where what program-lines page-lines: counts and reports a difference
    if ! diff "$3" "$4" > "$tmp/diff"; then
        echo "FAILED: $1 differs from $2 (< program, > page):"
        head -n 12 "$tmp/diff" | sed 's/^/    /'
        bad=$((bad + 1))
    fi
}

find . -name '*.md' -not -path './.git/*' -not -path './build/*' | sed 's|^\./||' | sort > "$tmp/pages"
: > "$tmp/shown"
while IFS= read -r md; do
    grep -n '^<!-- snippet: [^ ]* [A-Za-z0-9_]* -->$' "$md" > "$tmp/markers"
    while IFS= read -r m; do
        line=${m%%:*}
        m=${m#*:<!-- snippet: }
        m=${m% -->}
        src=${m% *} name=${m#* }
        checked=$((checked + 1))
        echo "$src $name" >> "$tmp/shown"
        if [ ! -f "$src" ]; then
            echo "FAILED: $md:$line shows $src, which does not exist"
            bad=$((bad + 1))
            continue
        fi
        if ! region "$src" "$name" > "$tmp/code"; then
            echo "FAILED: $md:$line shows region '$name' of $src, which has no /* snippet: $name */ line"
            bad=$((bad + 1))
            continue
        fi
        # the fenced block right after the marker
        awk -v from="$line" 'NR == from + 1 { if ($0 !~ /^```/) exit 4; on = 1; next }
                             on && /^```[ \t]*$/ { exit }
                             on { print }' "$md" > "$tmp/doc" || {
            echo "FAILED: $md:$line: no fenced code block right after the snippet marker"
            bad=$((bad + 1))
            continue
        }
        same "$md:$line" "region '$name' of $src" "$tmp/code" "$tmp/doc"
    done < "$tmp/markers"
    grep -n '^<!-- output: [^ ]*\( [^>]*\)\{0,1\} -->$' "$md" > "$tmp/markers"
    while IFS= read -r m; do
        line=${m%%:*}
        m=${m#*:<!-- output: }
        m=${m% -->}
        src=${m%% *} args=
        [ "$src" != "$m" ] && args=${m#* }
        outputs=$((outputs + 1))
        bin=$tmp/$(echo "$src" | tr '/.' '__')
        if [ ! -x "$bin" ] && ! ${CC:-gcc} -O0 -std=c99 -I. "$src" -o "$bin" -lm 2> "$tmp/build"; then
            echo "FAILED: $md:$line shows the output of $src, which does not build:"
            head -n 12 "$tmp/build" | sed 's/^/    /'
            bad=$((bad + 1))
            continue
        fi
        # shellcheck disable=SC2086 # the marker's arguments are words
        "$bin" $args > "$tmp/out" 2>&1 || echo "(exit status $?)" >> "$tmp/out"
        # the lines up to the end marker
        awk -v from="$line" 'NR > from && /^<!-- end output -->$/ { found = 1; exit }
                             NR > from { print }
                             END { exit !found }' "$md" > "$tmp/doc" || {
            echo "FAILED: $md:$line: no <!-- end output --> line after the output marker"
            bad=$((bad + 1))
            continue
        }
        same "$md:$line" "the output of $src $args" "$tmp/out" "$tmp/doc"
    done < "$tmp/markers"
done < "$tmp/pages"
# every marked region is shown somewhere
grep -l '^[ \t]*/\* snippet: [A-Za-z0-9_]* \*/[ \t]*$' examples/*.c tests/*.c studies/*.c 2> /dev/null |
    while IFS= read -r src; do
        sed -n 's|^[ \t]*/\* snippet: \([A-Za-z0-9_]*\) \*/[ \t]*$|\1|p' "$src" | while IFS= read -r name; do
            grep -qx "$src $name" "$tmp/shown" ||
                echo "FAILED: region '$name' of $src is marked as a snippet but no page shows it"
        done
    done > "$tmp/orphans"
cat "$tmp/orphans"
bad=$((bad + $(wc -l < "$tmp/orphans")))
if [ "$checked" -eq 0 ]; then
    echo "tests/check_doc_snippets.sh: no snippet markers found in the Markdown pages"
    exit 1
fi
if [ "$bad" -gt 0 ]; then
    echo "tests/check_doc_snippets.sh: $bad problems in $checked snippets"
    exit 1
fi
echo "tests/check_doc_snippets.sh: all $checked snippets equal the lines of their programs, all $outputs outputs are what their programs print"
