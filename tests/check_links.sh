#!/bin/sh
# tests/check_links.sh - every relative link and image of the Markdown files
# (README.md, docs/, data/, examples/, ...) points at a file or folder of the
# repository: a page moved or renamed without its links fails here (exit 1,
# listing file:line and the missing target). Web links and same-page anchors
# are not checked; the anchor part of a link to another page is dropped.
cd "$(dirname "$0")/.." || exit 2
bad=0
checked=0
list=$(mktemp) || exit 2
trap 'rm -f "$list" "$list.links"' EXIT
find . -name '*.md' -not -path './.git/*' -not -path './build/*' > "$list"
while IFS= read -r md; do
    dir=$(dirname "$md")
    # one "line:target" per link: ](target) or ](target "title"), on any line
    grep -n -o '](\([^) ]*\)' "$md" | sed 's/^\([0-9]*\):](/\1:/' > "$list.links"
    while IFS= read -r link; do
        line=${link%%:*}
        target=${link#*:}
        case $target in
        http://* | https://* | mailto:* | \#* | '') continue ;;
        esac
        target=${target%%#*}
        checked=$((checked + 1))
        if [ ! -e "$dir/$target" ]; then
            echo "FAILED: $md:$line links to $target, which does not exist"
            bad=$((bad + 1))
        fi
    done < "$list.links"
done < "$list"
if [ "$bad" -gt 0 ]; then
    echo "tests/check_links.sh: $bad of $checked relative links broken"
    exit 1
fi
echo "tests/check_links.sh: all $checked relative links of the Markdown files resolve"
