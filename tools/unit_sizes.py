#!/usr/bin/env python3
"""Sizes of the C++ units of SRI-GVINS: the largest source files and the longest functions.

    tools/unit_sizes.py [--root DIR] [--top N] [--check] [--check-dirs vio,fusion,gnss]
                        [--max-file-lines 1000] [--max-function-lines 150] [FILE...]

Without --check it prints the N largest files (physical lines) and the N longest function bodies
of every C++ source and header under the module folders, apps/, tests/ and bench/ (or of the FILEs
given). With --check it lists the files and functions of the --check-dirs folders over the limits
and exits with 1 if there is any (the project's rule: files under ~1000 lines, functions under
~150; docs/CONVENTIONS.md).

A function's length is the number of physical lines from the first line of its declarator (its
name and parameter list; a leading template<...> line is not counted) to its closing brace.
Functions are found by a scan of the brace structure of the code with comments, string and
character literals (raw strings too) and preprocessor lines blanked out: at namespace or class
scope, a '{' that follows a parameter list (possibly with const/noexcept/override/final/-> R
after it, or a constructor's initialiser list) opens a function body; everything inside it (blocks,
lambdas, local classes) belongs to that function. A lambda stored in a variable at namespace scope
counts as a function named after the variable; GoogleTest's TEST(...) bodies count as functions
named TEST(Suite, Name). Aggregate initialisers ('= {', 'x{...}') and namespace/class/enum bodies
are not functions.
"""

import argparse
import os
import re
import sys

SOURCE_DIRS = ["base", "ephemeris", "rtcm", "sri", "gnss", "vio", "sim", "fusion", "apps", "tests", "bench",
               "examples", "tools"]
EXTENSIONS = (".cpp", ".cc", ".cxx", ".hpp", ".h", ".hh")
CONTROL = {"if", "for", "while", "switch", "catch", "do", "else", "try", "return", "sizeof", "decltype",
           "alignof", "noexcept", "requires", "static_assert"}


def blank_out(text):
    """Comments, literals and preprocessor lines replaced by spaces; newlines kept."""
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if at_line_start and c == "#":
            # preprocessor directive, with backslash continuations
            while i < n:
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                if text[i] == "\n":
                    break
                if text.startswith("/*", i):  # a comment inside a directive
                    j = text.find("*/", i + 2)
                    j = n if j < 0 else j + 2
                    out.append(re.sub(r"[^\n]", " ", text[i:j]))
                    i = j
                    continue
                out.append(" ")
                i += 1
            continue
        at_line_start = False
        if c == "\n":
            out.append(c)
            at_line_start = True
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")
                                                         or re.search(r"(^|\W)(u8|u|U|L)$", text[max(0, i - 3):i])):
            m = re.match(r'R"([^ ()\\\t\n]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = ")" + m.group(1) + '"'
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum() and text[i - 1] not in "uUL")):
            # string or character literal (a ' between digits is a digit separator)
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_template_prefix(h):
    """Removes leading 'template <...>' clauses (balanced angle brackets)."""
    while True:
        m = re.match(r"\s*template\s*<", h)
        if not m:
            return h
        depth, j = 1, m.end()
        while j < len(h) and depth:
            if h[j] == "<":
                depth += 1
            elif h[j] == ">":
                depth -= 1
            j += 1
        h = h[j:]


def paren_groups(h):
    """(start, end) of the top-level (...) groups of h."""
    groups, depth, start = [], 0, 0
    for j, ch in enumerate(h):
        if ch == "(":
            if depth == 0:
                start = j
            depth += 1
        elif ch == ")" and depth:
            depth -= 1
            if depth == 0:
                groups.append((start, j + 1))
    return groups


def init_list_colon(h):
    """Index of a constructor initialiser list's ':' (a lone ':' after a top-level ')'), or -1."""
    depth, seen_paren = 0, False
    for j, ch in enumerate(h):
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
            if depth == 0 and ch == ")":
                seen_paren = True
        elif ch == ":" and depth == 0 and seen_paren:
            if (j + 1 < len(h) and h[j + 1] == ":") or (j > 0 and h[j - 1] == ":"):
                continue
            return j
    return -1


QUALIFIERS = re.compile(r"(\s*(const|volatile|noexcept\s*(\([^()]*\))?|override|final|mutable|&&|&|try|"
                        r"->\s*[\w:<>,\s*&]+))*\s*$")


def classify(header):
    """For a '{' at namespace/class scope: ('function', name, declarator offset), ('scope',),
    ('member-init',) for a brace inside a constructor's initialiser list, or ('init',)."""
    h = strip_template_prefix(header)
    h = re.sub(r"^\s*((public|private|protected)\s*:\s*)+", "", h)
    hs = h.strip()
    if not hs:
        return ("init",)  # a bare block or an initialiser continuing an expression
    if re.match(r"(typedef\s+)?(inline\s+)?(namespace|class|struct|union|enum)\b", hs) and "(" not in hs:
        return ("scope",)
    if re.match(r"extern\s*(\"\")?\s*$", hs) or hs.startswith("namespace"):
        return ("scope",)
    if re.match(r"(class|struct|union)\b", hs) and "=" not in hs:
        return ("scope",)  # e.g. a base class with a parenthesised template argument
    colon = init_list_colon(hs)
    if colon >= 0:
        tail = hs[colon + 1:].rstrip()
        if tail.endswith(")") or tail.endswith("}"):
            return function_of(hs[:colon], header)
        return ("member-init",)
    core = QUALIFIERS.sub("", hs)
    if core.endswith(")") and not hs.rstrip().endswith("="):
        return function_of(core, header)
    return ("init",)


def function_of(decl, header):
    groups = paren_groups(decl)
    if not groups:
        return ("init",)
    start, end = groups[-1]
    before = decl[:start].rstrip()
    m = re.search(r"(operator\s*(\(\)|\[\]|[^\s\w(]+|\s+[\w:<>*&\s]+?))\s*$", before)
    if m:
        name_m = re.search(r"([\w:~]*" + re.escape(m.group(1)) + r")$", before)
        name = name_m.group(1) if name_m else m.group(1)
    else:
        m = re.search(r"([~\w]+(\s*<[^<>()]*>)?(\s*::\s*~?\w+(\s*<[^<>()]*>)?)*)\s*$", before)
        if m is None:
            # a lambda stored in a variable: `auto f = [...](...)`
            lm = re.search(r"(\w+)\s*=\s*\[[^\]]*\]\s*(<[^>]*>)?\s*$", before)
            if not lm:
                return ("init",)
            name = lm.group(1)
        else:
            name = re.sub(r"\s+", "", m.group(1))
    last = name.split("::")[-1]
    if last in CONTROL:
        return ("init",)
    if re.fullmatch(r"[A-Z][A-Z0-9]*_[A-Z0-9_]*|[A-Z][A-Z0-9]{3,}", name):  # a macro: TEST(Suite, Name)
        name += re.sub(r"\s+", " ", decl[start:end])
    return ("function", name)


def scan_functions(text):
    """[(name, first_line, last_line)] of the function bodies of a C++ text."""
    code = blank_out(text)
    stack = ["scope"]
    header_parts = []
    functions = []
    open_fn = None  # (name, first line, depth)
    line = 1
    i, n = 0, len(code)
    line_of = []  # for each header char, its line
    while i < n:
        c = code[i]
        top = stack[-1]
        if c == "\n":
            line += 1
        if top == "scope":
            if c == "{":
                header = "".join(header_parts)
                kind = classify(header)
                if kind[0] == "function":
                    # first line: the declaration's first non-blank character after template<...>
                    rest = re.sub(r"^\s*((public|private|protected)\s*:)?\s*", "", strip_template_prefix(header))
                    off = len(header) - len(rest)
                    first = line_of[off] if off < len(line_of) else line
                    open_fn = (kind[1], first)
                    stack.append("function")
                elif kind[0] == "scope":
                    stack.append("scope")
                    header_parts, line_of = [], []
                elif kind[0] == "member-init":
                    stack.append("member-init")
                    header_parts.append("{")
                    line_of.append(line)
                else:
                    stack.append("init")
                if kind[0] in ("function", "init"):
                    header_parts, line_of = [], []
            elif c == "}":
                if len(stack) > 1:
                    stack.pop()
                header_parts, line_of = [], []
            elif c == ";":
                header_parts, line_of = [], []
            else:
                header_parts.append(c)
                line_of.append(line)
        elif top == "member-init":
            header_parts.append(c)
            line_of.append(line)
            if c == "{":
                stack.append("member-init")
            elif c == "}":
                stack.pop()
        else:  # function body, block or initialiser
            if c == "{":
                stack.append("block" if top != "init" else "init")
            elif c == "}":
                stack.pop()
                if top == "function":
                    functions.append((open_fn[0], open_fn[1], line))
                    open_fn = None
                    header_parts, line_of = [], []
                elif top == "init" and stack[-1] == "scope":
                    header_parts, line_of = [], []
        i += 1
    return functions


def source_files(root, dirs):
    files = []
    for d in dirs:
        base = os.path.join(root, d)
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(x for x in dirnames if not x.startswith("build") and x != "data")
            for f in sorted(filenames):
                if f.endswith(EXTENSIONS):
                    files.append(os.path.join(dirpath, f))
    return files


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("files", nargs="*", help="C++ files (default: every source under --root's module folders)")
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    p.add_argument("--top", type=int, default=10, help="how many files and functions to list (default 10)")
    p.add_argument("--check", action="store_true", help="list violations in --check-dirs; exit 1 if any")
    p.add_argument("--check-dirs", default="vio,fusion,gnss")
    p.add_argument("--max-file-lines", type=int, default=1000)
    p.add_argument("--max-function-lines", type=int, default=150)
    a = p.parse_args(argv)
    root = os.path.normpath(a.root)
    files = a.files or source_files(root, SOURCE_DIRS)
    rel = lambda f: os.path.relpath(f, root) if not a.files else f  # noqa: E731
    sizes, funcs = [], []
    for f in files:
        try:
            with open(f, encoding="utf-8", errors="replace") as fh:
                text = fh.read()
        except OSError as e:
            print(f"unit_sizes: {f}: {e.strerror}", file=sys.stderr)
            return 2
        sizes.append((text.count("\n") + (0 if text.endswith("\n") or not text else 1), rel(f)))
        for name, first, last in scan_functions(text):
            funcs.append((last - first + 1, rel(f), first, name))
    sizes.sort(key=lambda s: (-s[0], s[1]))
    funcs.sort(key=lambda s: (-s[0], s[1], s[2]))

    if not a.check:
        print(f"{len(files)} files, {sum(s[0] for s in sizes)} lines, {len(funcs)} functions")
        print("largest files (lines):")
        for lines, f in sizes[:a.top]:
            print(f"  {lines:6d}  {f}")
        print("longest functions (lines, first line to closing brace):")
        for lines, f, first, name in funcs[:a.top]:
            print(f"  {lines:6d}  {f}:{first}  {name}")
        return 0

    dirs = [os.path.normpath(d.strip()) for d in a.check_dirs.split(",") if d.strip()]
    inside = lambda f: any(f == d or f.startswith(d + "/") for d in dirs)  # noqa: E731
    big = [s for s in sizes if inside(s[1]) and s[0] > a.max_file_lines]
    long_ = [s for s in funcs if inside(s[1]) and s[0] > a.max_function_lines]
    print(f"files over {a.max_file_lines} lines in {', '.join(dirs)}: {len(big)}")
    for lines, f in big:
        print(f"  {lines:6d}  {f}")
    print(f"functions over {a.max_function_lines} lines in {', '.join(dirs)}: {len(long_)}")
    for lines, f, first, name in long_:
        print(f"  {lines:6d}  {f}:{first}  {name}")
    return 1 if big or long_ else 0


if __name__ == "__main__":
    sys.exit(main())
