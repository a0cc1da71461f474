#!/usr/bin/env python3
"""Lists the longest Rust functions in the workspace, longest first.

    python3 xtask/scripts/longest_functions.py            # the ten longest, src only
    python3 xtask/scripts/longest_functions.py --top 30
    python3 xtask/scripts/longest_functions.py --tests    # also tests/, benches/ and #[cfg(test)] code

Each line reads `LINES PATH:LINE NAME`: LINES is the span of the function's body, from the line of its
opening brace to the line of its closing brace (both counted); PATH:LINE is where the `fn` keyword
stands; NAME is the function's name (methods and functions nested inside functions count on their
own, and their lines count again inside the function that holds them).

Braces are matched on a token stream that skips comments (line, block and nested block), string
literals (plain, byte, C and raw, with any number of `#`), and character literals (told apart from
lifetimes). A `fn` counts when an identifier follows it (so `fn(u8) -> u8` pointer types do not) and
its signature ends in a body `{` rather than in `;` (trait declarations).

By default only `crates/*/src/**` and `xtask/src/**` are read, and inside them a function or module
under `#[test]` or `#[cfg(test)]` is left out. Standard library only, so that anyone can rerun it.
"""

import argparse
import os
import sys

IDENT_START = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_")
IDENT_CHAR = IDENT_START | set("0123456789")


def tokens(text):
    """Yields (kind, value, line) for identifiers ('id'), punctuation ('p') and literals ('lit').

    Comments and whitespace produce nothing; a literal produces one 'lit' token, so braces inside it
    never count."""
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif c in " \t\r":
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    line += text[i] == "\n"
                    i += 1
        elif c == '"' or (c in "bcr" and _raw_or_prefixed_string(text, i)):
            start_line = line
            i, line = _skip_string(text, i, line)
            yield ("lit", '""', start_line)
        elif c == "'":
            j = _char_literal_end(text, i)
            if j is None:  # a lifetime or a label: `'a`
                i += 1
            else:
                line += text.count("\n", i, j)
                i = j
                yield ("lit", "''", line)
        elif c == "b" and text.startswith("b'", i):
            j = _char_literal_end(text, i + 1)
            i = i + 2 if j is None else j
            yield ("lit", "''", line)
        elif c in IDENT_START:
            j = i + 1
            while j < n and text[j] in IDENT_CHAR:
                j += 1
            yield ("id", text[i:j], line)
            i = j
        else:
            yield ("p", c, line)
            i += 1


def _raw_or_prefixed_string(text, i):
    """True at `b"`, `c"`, `r"`, `r#"`, `br"`, `br#"`, `cr#"` (not at an identifier that merely starts
    with those letters, since the caller only asks at an identifier's first character)."""
    if i > 0 and text[i - 1] in IDENT_CHAR:
        return False
    j = i
    if text[j] in "bc":
        j += 1
    if j < len(text) and text[j] == "r":
        j += 1
        while j < len(text) and text[j] == "#":
            j += 1
    return j > i and j < len(text) and text[j] == '"'


def _skip_string(text, i, line):
    """Returns the index after the string literal starting at i, and the line it ends on."""
    hashes = None
    while text[i] != '"':
        if text[i] == "r":
            hashes = 0
        elif text[i] == "#":
            hashes += 1
        i += 1
    i += 1
    if hashes is not None:
        end = '"' + "#" * hashes
        j = text.find(end, i)
        j = len(text) if j < 0 else j
        return j + len(end), line + text.count("\n", i, j)
    while i < len(text):
        c = text[i]
        if c == "\\":
            line += text[i + 1] == "\n" if i + 1 < len(text) else 0
            i += 2
            continue
        if c == "\n":
            line += 1
        elif c == '"':
            return i + 1, line
        i += 1
    return i, line


def _char_literal_end(text, i):
    """The index after a character literal starting at the quote at i, or None for a lifetime."""
    if i + 1 >= len(text):
        return None
    if text[i + 1] == "\\":
        j = text.find("'", i + 3)
        # An escape is short: `'\n'`, `'\x7f'`, `'\u{10FFFF}'`.
        return j + 1 if 0 < j - i <= 12 else None
    if i + 2 < len(text) and text[i + 2] == "'":
        return i + 3
    # A non-ASCII character is one code point in a str, so the case above covers it too.
    return None


def functions(text, skip_tests):
    """Yields (name, fn_line, open_line, close_line) for every fn with a body in the text."""
    toks = list(tokens(text))
    test_ranges = []  # token index ranges of #[test] / #[cfg(test)] items, when skipped
    found = []
    attr_is_test = False
    i = 0
    while i < len(toks):
        kind, value, line = toks[i]
        if kind == "p" and value == "#" and i + 1 < len(toks) and toks[i + 1][1] in ("[", "!"):
            # An attribute: read it to its closing bracket and note whether it marks test code.
            j = i + 1 if toks[i + 1][1] == "[" else i + 2
            depth, words = 0, []
            while j < len(toks):
                if toks[j][1] == "[":
                    depth += 1
                elif toks[j][1] == "]":
                    depth -= 1
                    if depth == 0:
                        break
                elif toks[j][0] == "id":
                    words.append(toks[j][1])
                j += 1
            if words in (["test"], ["cfg", "test"]) or words[:2] == ["cfg", "test"]:
                attr_is_test = True
            i = j + 1
            continue
        if kind == "id" and value in ("fn", "mod", "impl") or (kind == "p" and value in ";{}"):
            if attr_is_test and kind == "id":
                end = _item_end(toks, i)
                test_ranges.append((i, end))
            attr_is_test = False
        if kind == "id" and value == "fn" and i + 1 < len(toks) and toks[i + 1][0] == "id":
            name = toks[i + 1][1]
            j, depth = i + 2, 0
            while j < len(toks):
                v = toks[j][1]
                if toks[j][0] == "p":
                    if v in "([":
                        depth += 1
                    elif v in ")]":
                        depth -= 1
                    elif v == ";" and depth == 0:
                        j = None
                        break
                    elif v == "{" and depth == 0:
                        break
                j += 1
            if j is not None and j < len(toks):
                close = _matching_brace(toks, j)
                found.append((i, name, line, toks[j][2], toks[close][2]))
        i += 1
    for index, name, fn_line, open_line, close_line in found:
        if skip_tests and any(a <= index <= b for a, b in test_ranges):
            continue
        yield name, fn_line, open_line, close_line


def _item_end(toks, i):
    """The token index that ends the item starting at i: its body's closing brace, or its `;`."""
    j = i
    while j < len(toks):
        if toks[j][0] == "p" and toks[j][1] == ";":
            return j
        if toks[j][0] == "p" and toks[j][1] == "{":
            return _matching_brace(toks, j)
        j += 1
    return len(toks) - 1


def _matching_brace(toks, j):
    depth = 0
    while j < len(toks):
        if toks[j][0] == "p":
            if toks[j][1] == "{":
                depth += 1
            elif toks[j][1] == "}":
                depth -= 1
                if depth == 0:
                    return j
        j += 1
    return len(toks) - 1


def rust_files(root, include_tests):
    roots = [os.path.join(root, "crates"), os.path.join(root, "xtask")]
    for top in roots:
        for dirpath, dirnames, filenames in os.walk(top):
            dirnames[:] = sorted(d for d in dirnames if d not in ("target", ".git"))
            rel = os.path.relpath(dirpath, root).split(os.sep)
            in_src = "src" in rel
            if not in_src and not include_tests:
                continue
            for f in sorted(filenames):
                if f.endswith(".rs"):
                    yield os.path.join(dirpath, f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--top", type=int, default=10, help="how many to list (default 10)")
    parser.add_argument(
        "--tests",
        action="store_true",
        help="also read tests/, benches/ and examples/, and #[test]/#[cfg(test)] code in src/",
    )
    parser.add_argument(
        "--root",
        default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."),
        help="the workspace root (default: two folders above this script)",
    )
    args = parser.parse_args()
    root = os.path.realpath(args.root)
    rows = []
    for path in rust_files(root, args.tests):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        rel = os.path.relpath(path, root)
        for name, fn_line, open_line, close_line in functions(text, not args.tests):
            rows.append((close_line - open_line + 1, rel, fn_line, name))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    for lines, rel, fn_line, name in rows[: args.top]:
        print(f"{lines:5} {rel}:{fn_line} {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
