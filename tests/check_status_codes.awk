# tests/check_status_codes.awk - the status codes the documentation names
# are codes the named functions can return. Run by tests/check_status_codes.sh
# as  awk -f tests/check_status_codes.awk sph_kernel.h page.md ...
# (the header first); POSIX awk (mawk, gawk, busybox).
#
# 1. The codes: the X(...) entries of the header's SPH_STATUS_LIST. Every
#    SPH_E... name (SPH_E and capitals) in the pages, their code blocks and
#    the header's comments must be one of them.
# 2. What a function can return. The header is read as it is laid out
#    (clang-format): a function body opens with a line "{" and closes with a
#    line "}", both at column 0, after a signature that starts at column 0
#    (or the function is one line); a macro is a #define with its
#    continuation lines. A function can return the codes written in its
#    body (comments and strings left out) and, transitively, those of every
#    function and macro its body names. That over-counts (a callee's code
#    may be tested and replaced), so the check never fails a true
#    statement; it fails a code that nothing the function reaches mentions.
#    The functions a text can be tied to are those returning int (the
#    status-returning ones, public or internal); sph_strerror, which names
#    every code, returns a string.
# 3. Which functions a mention is tied to: the first of these levels that
#    names an int function.
#      - A unit: a sentence (text up to . ! ? before a capital, a backtick or
#        a parenthesis), a clause up to "; ", a table cell. With it: in the
#        header, the function the comment documents (the comment right
#        above its signature) or sits in; in a table row, the functions its
#        first cell names (an API table's row is about its function).
#        In a code block of a page: a code compared (==, !=, case) or named
#        in a comment is tied to the function whose status the block last
#        assigned or returned (st = sph_f(...), return sph_f(...)), else to
#        the functions the comment names; a code passed beside a message
#        that names a function (fail("sph_h_solve", SPH_EINVAL)) to that
#        function; any other code that the block's own code returns or
#        passes on (return SPH_ESIZE;) is the caller's own.
#      - The heading the text is under (a page's heading that names
#        functions, "## The grad-h forces (`sph_gradh_forces`, ...)"), or
#        the header's numbered section.
#      - The page (every function it names); for the header, the library.
#    The code must be one that at least one of the tied functions can
#    return, and, tied to nothing closer, one some function returns. The
#    comment that introduces SPH_STATUS_LIST defines the codes: tied to
#    nothing.
# Output: "FAILED: file:line: ..." per stale mention, then a summary line;
# exit status 1 when anything failed.

function add(set, w) { return index(set, " " w " ") ? set : set w " " }
function has(set, w) { return index(set, " " w " ") > 0 }
function empty(set) { return set !~ /[^ ]/ }

# The identifiers of text s that start with sph_ or SPH_, as a set " a b ".
function idents(s,    out, t) {
    out = " "
    while (match(s, /[A-Za-z_][A-Za-z0-9_]*/)) {
        t = substr(s, RSTART, RLENGTH)
        s = substr(s, RSTART + RLENGTH)
        if (t ~ /^(sph|SPH)_/) out = add(out, t)
    }
    return out
}

# The status names of text s (SPH_E and capitals, a whole token), as a set.
function codes_of(s,    out, t, pre) {
    out = " "
    while (match(s, /[A-Za-z0-9_]*SPH_E[A-Z]+[A-Za-z0-9_]*/)) {
        t = substr(s, RSTART, RLENGTH)
        s = substr(s, RSTART + RLENGTH)
        if (t ~ /^SPH_E[A-Z]+$/) out = add(out, t)
    }
    return out
}

# The int functions named in text s, as a set.
function funcs_in(s,    ids, n, k, a, out) {
    ids = idents(s)
    n = split(ids, a, " ")
    out = " "
    for (k = 1; k <= n; ++k)
        if (a[k] in intfn) out = add(out, a[k])
    return out
}

# What the functions of set fs can return, together.
function returns_of(fs,    n, k, a, out, m, c, b) {
    n = split(fs, a, " ")
    out = " "
    for (k = 1; k <= n; ++k) {
        m = split(cl[a[k]], b, " ")
        for (c = 1; c <= m; ++c) out = add(out, b[c])
    }
    return out
}

# A set's words, sorted, once each, for a message.
function sorted(set,    n, a, i, j, t, out) {
    n = split(set, a, " ")
    for (i = 2; i <= n; ++i)
        for (j = i; j > 1 && a[j - 1] > a[j]; --j) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
    out = ""
    for (i = 1; i <= n; ++i) if (i == 1 || a[i] != a[i - 1]) out = out (out != "" ? " " : "") a[i]
    return out
}

# check(file, line, codes, l1, w1, l2, w2, l3, w3): each code of the set
# against the first nonempty function set of l1, l2, l3, else the library
# (w1..w3 say what each level is, for the message).
function check(file, line, cs, l1, w1, l2, w2, l3, w3,    n, a, k, fs, why, r) {
    n = split(cs, a, " ")
    if (n == 0) return
    if (!empty(l1)) { fs = l1; why = w1 }
    else if (!empty(l2)) { fs = l2; why = w2 }
    else if (!empty(l3)) { fs = l3; why = w3 }
    else { fs = allint; why = "" }
    r = returns_of(fs)
    for (k = 1; k <= n; ++k) {
        mentions++
        if (!(a[k] in known)) {
            print "FAILED: " file ":" line ": " a[k] " is not a status code of sph_kernel.h (SPH_STATUS_LIST)"
            bad++
        } else if (!has(r, a[k])) {
            if (why == "")
                print "FAILED: " file ":" line ": " a[k] " is returned by no function of sph_kernel.h"
            else
                print "FAILED: " file ":" line ": " a[k] " is tied to " sorted(fs) " (" why "), which cannot return it (can: " sorted(r) ")"
            bad++
        }
    }
}

# ---- reading -----------------------------------------------------------
FNR == 1 { files[++nfiles] = FILENAME }
{ text[FILENAME, FNR] = $0; lines[FILENAME] = FNR }

# ---- the header ----------------------------------------------------------
# strip(s): CODE, the line without comments and with empty strings; CMT, its
# comment text; CID, the number of the comment the line's text belongs to.
# incom carries an open comment to the next line.
function strip(s,    c, n, p, q, out, com, ch, nx) {
    out = ""
    com = ""
    CID = incom ? ncid : ""
    n = length(s)
    for (p = 1; p <= n; ++p) {
        ch = substr(s, p, 1)
        nx = substr(s, p + 1, 1)
        if (incom) {
            if (ch == "*" && nx == "/") { incom = 0; ++p; com = com " "; continue }
            com = com ch
            continue
        }
        if (ch == "/" && nx == "*") { incom = 1; ++p; out = out " "; if (CID == "") CID = ++ncid; continue }
        if (ch == "/" && nx == "/") { com = com substr(s, p + 2); if (CID == "") CID = ++ncid; break }
        if (ch == "\"" || ch == "'") {
            for (q = p + 1; q <= n; ++q) {
                c = substr(s, q, 1)
                if (c == "\\") { ++q; continue }
                if (c == ch) break
            }
            out = out ch ch
            p = q
            continue
        }
        out = out ch
    }
    CODE = out
    CMT = com
}

# parse_header(f): code[], cmt[], cid[], wascom[] (a line inside or opening
# a comment), hsect[] (numbered section), owner[] (the function a line
# belongs to, "#NAME" in a macro), direct[] and refs[] of every function and
# macro, intfn[], doc[] (the function a comment line documents), known[].
function parse_header(f,    i, n, s, was, pend, pstart, sect, fname, infn, macro, mname, rest, ids) {
    n = lines[f]
    incom = 0
    sect = 0
    infn = 0
    pend = ""
    macro = 0
    mname = ""
    for (i = 1; i <= n; ++i) {
        s = text[f, i]
        was = incom
        strip(s)
        code[i] = CODE
        cmt[i] = CMT
        cid[i] = CID
        wascom[i] = was || CID != ""
        if (s ~ /^\/\* [0-9]+\. /) { sect = s; sub(/^\/\* /, "", sect); sub(/\..*/, "", sect); sect += 0 }
        hsect[i] = sect
        if (macro || CODE ~ /^[ \t]*#/) { # a preprocessor line and its continuations
            if (!macro) {
                mname = ""
                rest = ""
                if (CODE ~ /^[ \t]*#[ \t]*define[ \t]/) {
                    mname = CODE
                    sub(/^[ \t]*#[ \t]*define[ \t]+/, "", mname)
                    sub(/[^A-Za-z0-9_].*/, "", mname)
                    rest = CODE
                    sub(/^[ \t]*#[ \t]*define[ \t]+[A-Za-z0-9_]+/, "", rest)
                    if (mname == "SPH_STATUS_LIST") statuslist = i
                }
            } else rest = CODE
            macro = 1
            if (mname == "SPH_STATUS_LIST") {
                ids = rest
                while (match(ids, /X\(SPH_[A-Z]+,/)) {
                    known[substr(ids, RSTART + 2, RLENGTH - 3)] = 1
                    ids = substr(ids, RSTART + RLENGTH)
                }
            } else if (mname != "") {
                refs[mname] = refs[mname] idents(rest)
                direct[mname] = direct[mname] codes_of(rest)
                defined[mname] = 1
            }
            if (CODE !~ /\\[ \t]*$/) macro = 0
            pend = ""
            owner[i] = infn ? fname : (mname != "" ? "#" mname : "")
            continue
        }
        if (infn) {
            owner[i] = fname
            if (CODE ~ /^}[ \t]*$/) { infn = 0; pend = ""; continue }
            refs[fname] = refs[fname] idents(CODE)
            direct[fname] = direct[fname] codes_of(CODE)
            continue
        }
        owner[i] = ""
        if (CODE ~ /^\{[ \t]*$/ && index(pend, "(") && pend !~ /=/) {
            start_fn(pend, pstart)
            infn = NAME != ""
            fname = NAME
            owner[i] = fname
            continue
        }
        if (CODE ~ /^[ \t]*$/) { pend = ""; continue }
        if (pend == "") pstart = i
        pend = pend " " CODE
        if (CODE ~ /\)[ \t]*\{.*\}[ \t]*$/ && pend !~ /=[^=]*\{/) { # a function on one line
            rest = pend
            start_fn(substr(rest, 1, index(rest, "{") - 1), pstart)
            owner[i] = NAME
            sub(/^[^{]*\{/, "", rest)
            refs[NAME] = refs[NAME] idents(rest)
            direct[NAME] = direct[NAME] codes_of(rest)
            pend = ""
            continue
        }
        if (CODE ~ /[;}][ \t]*$/) pend = ""
    }
}

# start_fn(sig, line): a function whose signature (the text before its body)
# starts at header line `line`: its NAME, intfn[] if it returns int, and
# doc[] for the comment that ends on the line above.
function start_fn(sig, line,    s, name, pre, j) {
    s = sig
    name = ""
    while (match(s, /[A-Za-z_][A-Za-z0-9_]*[ \t]*\(/)) {
        name = substr(s, RSTART, RLENGTH)
        s = substr(s, RSTART + RLENGTH) # before sub(), which may move RSTART
        sub(/[ \t]*\($/, "", name)
        if (name !~ /^(__attribute__|SPH_TARGET_[A-Z0-9]+|__declspec)$/) break
        name = ""
    }
    NAME = name
    if (name == "") return
    pre = substr(sig, 1, index(sig, name "(") > 0 ? index(sig, name "(") - 1 : index(sig, name) - 1)
    defined[name] = 1
    sectof[name] = hsect[line]
    if (pre ~ /(^|[ \t])int[ \t]*$/) intfn[name] = 1
    for (j = line - 1; j > 0 && wascom[j] && code[j] ~ /^[ \t]*$/; --j) doc[j] = name
}

# The transitive closure cl[] of direct[] over refs[].
function closure(    changed, n, k, a, f, m, c, b, r) {
    for (f in defined) {
        r = refs[f]
        refs[f] = " "
        n = split(r, a, " ")
        for (k = 1; k <= n; ++k) if (a[k] in defined && a[k] != f) refs[f] = add(refs[f], a[k])
        cl[f] = " "
        n = split(direct[f], a, " ")
        for (k = 1; k <= n; ++k) cl[f] = add(cl[f], a[k])
    }
    do {
        changed = 0
        for (f in defined) {
            n = split(refs[f], a, " ")
            for (k = 1; k <= n; ++k) {
                m = split(cl[a[k]], b, " ")
                for (c = 1; c <= m; ++c)
                    if (!has(cl[f], b[c])) { cl[f] = cl[f] b[c] " "; changed = 1 }
            }
        }
    } while (changed)
}

# ---- prose ----------------------------------------------------------------
# check_block(file, nb, attach, l2, w2, l3, w3): the block of nb lines in
# bl[] (line numbers in bn[]), unit by unit (a sentence, a clause up to
# "; ", a table cell), each against its own int functions and attach, then
# l2, l3 and the library.
function check_block(file, nb, attach, l2, w2, l3, w3,    k, joined, off, s, p, q, cut, unit, rest, sline, cs) {
    joined = ""
    for (k = 1; k <= nb; ++k) { start_at[k] = length(joined) + 1; joined = joined bl[k] " " }
    if (empty(codes_of(joined))) return
    off = 0
    s = joined
    while (s != "") {
        if (match(s, /([.!?][ \t]+[A-Z`(]|;[ \t]|[ \t]\|)/)) { cut = RSTART; unit = substr(s, 1, cut); rest = substr(s, cut + 1) }
        else { unit = s; rest = "" }
        cs = codes_of(unit)
        if (!empty(cs)) {
            match(unit, /SPH_E[A-Z]+/) # the line of the unit's first code
            p = off + RSTART
            sline = bn[1]
            for (q = 1; q <= nb; ++q) if (start_at[q] <= p) sline = bn[q]
            check(file, sline, cs, funcs_in(unit) attach, "the sentence names it", l2, w2, l3, w3)
        }
        off += length(unit)
        s = rest
    }
}

# The header's comments: one block per paragraph of a comment (up to an
# empty " *" line), an API row (" *   sph_name(", with its deeper-indented
# lines) a block of its own; a block ends with its comment.
function prose_header(f,    i, n, c, own, nb, prev, isrow, blank, attach, rowblk) {
    n = lines[f]
    nb = 0
    prev = ""
    for (i = 1; i <= n + 1; ++i) {
        if (i <= n) {
            c = cmt[i]
            sub(/^[ \t]*\*+[ \t]?/, "", c) # the comment's leading " * "
            own = i in doc ? doc[i] : owner[i]
            isrow = c ~ /^  +sph_[a-z0-9_]+\(/
            blank = cmt[i] !~ /[^ \t]/ || c ~ /^[ \t=*\/-]*$/ || i in skip
        }
        if (nb > 0 && (i > n || blank || isrow || own != prev || cid[i] != cid[bn[nb]] || rowblk && c !~ /^  /)) {
            attach = prev in intfn ? " " prev " " : " "
            check_block(f, nb, attach, sectfns[hsect[bn[1]]], "its section of the header", " ", "")
            nb = 0
        }
        if (i > n) break
        if (!blank) {
            if (nb == 0) rowblk = isrow
            bl[++nb] = c
            bn[nb] = i
        }
        prev = own
    }
}

# A Markdown page: code blocks line by line; outside them blocks of prose
# (paragraphs, list items, table rows).
function prose_page(f,    i, n, s, incode, nb, pageset, head, last, cs, cm, t, lv, k, j, row, lit) {
    n = lines[f]
    pageset = " "
    for (i = 1; i <= n; ++i) pageset = pageset funcs_in(text[f, i])
    incode = 0
    nb = 0
    head = " "
    for (i = 1; i <= n + 1; ++i) {
        s = i <= n ? text[f, i] : ""
        # a block ends at a blank line, a fence, a heading, a table row, a list item, an HTML comment
        if (nb > 0 && (i > n || s ~ /^[ \t]*$/ || s ~ /^[ \t]*```/ || s ~ /^#+ / || s ~ /^[ \t]*\|/ ||
                       s ~ /^[ \t]*([-*+]|[0-9]+\.)[ \t]/ || s ~ /^<!--/ || bl[1] ~ /^[ \t]*\|/)) {
            row = bl[1]
            if (row ~ /^[ \t]*\|/) { sub(/^[ \t]*\|/, "", row); sub(/\|.*/, "", row); row = funcs_in(row) }
            else row = " "
            check_block(f, nb, row, head, "the heading names it", pageset, "its page names it")
            nb = 0
        }
        if (i > n) break
        if (s ~ /^[ \t]*```/) { incode = !incode; last = ""; continue }
        if (incode) {
            t = s # st = sph_f(...), (st = sph_f(...)), return sph_f(...): the status the block holds
            while (match(t, /(=|return)[ \t]*sph_[a-z0-9_]+[ \t]*\(/)) {
                cm = substr(t, RSTART, RLENGTH)
                t = substr(t, RSTART + RLENGTH) # before sub(), which may move RSTART
                sub(/^(=|return)[ \t]*/, "", cm)
                sub(/[ \t]*\($/, "", cm)
                if (cm in intfn) last = cm
            }
            cs = " "
            t = s
            while (match(t, /([!=]=[ \t]*SPH_E[A-Z]+|SPH_E[A-Z]+[ \t]*[!=]=|case[ \t]+SPH_E[A-Z]+)/)) {
                cm = substr(t, RSTART, RLENGTH)
                t = substr(t, RSTART + RLENGTH)
                cs = cs codes_of(cm)
            }
            cm = index(s, "/*") ? substr(s, index(s, "/*")) : ""
            cs = cs codes_of(cm)
            check(f, i, cs, last != "" ? " " last " " : funcs_in(cm), last != "" ? "the code block's last call" : "the comment names it",
                  head, "the heading names it", pageset, "its page names it")
            t = s # a message that names a function beside a code: fail("sph_h_solve", SPH_EINVAL)
            lit = ""
            while (match(t, /"[^"]*"/)) {
                lit = lit " " substr(t, RSTART, RLENGTH)
                t = substr(t, 1, RSTART - 1) " " substr(t, RSTART + RLENGTH)
            }
            if (!empty(funcs_in(lit))) {
                sub(/\/\*.*/, "", t)
                check(f, i, codes_of(t), funcs_in(lit), "a message of the line names it", " ", "", " ", "")
            }
            k = split(codes_of(s), lv, " ") # the caller's own codes: status codes at all
            for (j = 1; j <= k; ++j)
                if (!(lv[j] in known)) { print "FAILED: " f ":" i ": " lv[j] " is not a status code of sph_kernel.h (SPH_STATUS_LIST)"; bad++ }
            continue
        }
        if (s ~ /^#+ /) { head = funcs_in(s); if (empty(codes_of(s))) continue }
        if (s ~ /^[ \t]*$/ || s ~ /^<!--/) continue
        bl[++nb] = s
        bn[nb] = i
    }
}

END {
    hdr = files[1]
    parse_header(hdr)
    if (statuslist == 0) { print "FAILED: " hdr " has no SPH_STATUS_LIST"; exit 1 }
    delete known["SPH_OK"]
    # the comment that introduces SPH_STATUS_LIST defines the codes: tied to nothing
    for (j = statuslist - 1; j > 0 && wascom[j] && code[j] ~ /^[ \t]*$/; --j) skip[j] = 1
    closure()
    allint = " "
    for (f in intfn) {
        allint = add(allint, f)
        sectfns[sectof[f]] = add(sectof[f] in sectfns ? sectfns[sectof[f]] : " ", f)
    }
    # the parse against what the code says: sph_kernel_check returns SPH_EKERNEL and SPH_EDIM and nothing else,
    # sph_time_step SPH_EVALUE and not SPH_ESIZE; over a hundred int functions
    nint = split(allint, tmp, " ")
    if (nint < 100 || sorted(cl["sph_kernel_check"]) != "SPH_EDIM SPH_EKERNEL" || !has(cl["sph_time_step"], "SPH_EVALUE") ||
        has(cl["sph_time_step"], "SPH_ESIZE")) {
        print "FAILED: the layout of " hdr " is not what this check reads: " nint " int functions; sph_kernel_check can return \"" \
              sorted(cl["sph_kernel_check"]) "\" (expected: SPH_EDIM SPH_EKERNEL), sph_time_step \"" sorted(cl["sph_time_step"]) "\""
        exit 1
    }
    prose_header(hdr)
    for (k = 2; k <= nfiles; ++k) prose_page(files[k])
    if (bad > 0) {
        print "tests/check_status_codes.sh: " bad " stale status codes in " mentions " mentions (" nint " status-returning functions)"
        exit 1
    }
    print "tests/check_status_codes.sh: all " mentions " status codes named in the pages and the header's comments are ones " \
          "the functions they are tied to can return (" nint " status-returning functions)"
}
