#!/usr/bin/env python3
"""The longest functions of the production code, by lines from the opening line of the
definition to its closing brace (a text scan, not a parser: comments and strings are
blanked, namespace and class braces do not count as functions).

  scripts/longest_functions.py [--most N] [--over LINES] [FOLDER ...]

Default folders: the library's, app/ and python/. Exit 1 when --over is given and a
function is longer.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDERS = ["core", "elements", "bodies", "joints", "forces", "builders", "integrators", "analysis", "simulation",
           "sensitivity", "fe_import", "scene", "linkage", "tensegrity", "viewer", "results", "app", "python"]
SCOPES = re.compile(r"^\s*(namespace\b|(template\s*<.*>\s*)?(class|struct|union|enum)\b|extern\s+\"C\")")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try)\b")


def blank(text):
    """Comments, strings and character literals replaced by spaces (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + (m.group(1) if m else "") + '"', i)
            j = n if end < 0 else end + len(m.group(1) if m else "") + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", text[i:j + 1])); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def functions(path):
    text = blank(open(path, encoding="utf-8", errors="replace").read())
    text = re.sub(r"^[ \t]*#.*$", "", text, flags=re.M)  # preprocessor lines
    stack = []  # per open brace: ("scope" | "function" | "block", start line, name)
    found = []
    pending, pending_line, line = "", 1, 1  # the text since the last ; { or }, and its first line
    for c in text:
        if c == "{":
            head = pending.strip()
            if any(s[0] == "function" for s in stack):
                stack.append(("block", line, ""))
            elif "(" in head and not SCOPES.match(head) and not CONTROL.match(head) and not head.endswith("="):
                name = re.sub(r"\s+", " ", head.split("(")[0]).strip().split(" ")[-1]
                start = pending_line + pending[:len(pending) - len(pending.lstrip())].count("\n")
                stack.append(("function", start, name))
            else:
                stack.append(("scope", line, ""))
            pending, pending_line = "", line
        elif c == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "function":
                    found.append((line - start + 1, os.path.relpath(path, ROOT), start, name))
            pending, pending_line = "", line
        elif c == ";":
            pending, pending_line = "", line
        else:
            pending += c
        if c == "\n":
            line += 1
    return found


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--most", type=int, default=10)
    p.add_argument("--over", type=int)
    p.add_argument("folders", nargs="*", default=FOLDERS)
    a = p.parse_args()
    found = []
    for folder in a.folders:
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            if "node_modules" in dirpath:
                continue
            for f in sorted(files):
                if f.endswith((".cpp", ".hpp")):
                    found += functions(os.path.join(dirpath, f))
    found.sort(reverse=True)
    for length, path, start, name in found[:a.most]:
        print(f"{length:5d}  {path}:{start}  {name}")
    if a.over is not None:
        over = [f for f in found if f[0] > a.over]
        print(f"{len(over)} functions longer than {a.over} lines")
        return 1 if over else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
