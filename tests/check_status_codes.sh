#!/bin/sh
# tests/check_status_codes.sh - every status code that the Markdown pages
# (README.md, docs/, ...), their code blocks and the comments of
# sph_kernel.h name is a code of the header's SPH_STATUS_LIST, and one that
# the function the text ties it to can return: the codes that function's
# body and everything it calls mention, read from the header. How a mention
# is tied to functions (its sentence, the code block's last call, the
# heading, the page) is described at the top of tests/check_status_codes.awk.
# Fails (exit 1) naming file:line, the code, the functions it was tied to and
# the codes they can return. Needs awk only (under a second).
cd "$(dirname "$0")/.." || exit 2
pages=$(find . -name '*.md' -not -path './.git/*' -not -path './build/*' | sed 's|^\./||' | sort)
# shellcheck disable=SC2086 # one word per page: the repository's page names have no blanks
awk -f tests/check_status_codes.awk sph_kernel.h $pages
