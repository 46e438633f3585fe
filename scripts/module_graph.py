#!/usr/bin/env python3
"""Top-level module graph of one Rust crate, and a check that it has no cycle.

Usage: scripts/module_graph.py CRATE_DIR [--mermaid] [--with-tests]

Reads every `.rs` file under CRATE_DIR/src, resolves `crate::…` and `super::…` paths (in `use`
items, brace groups included, and inline paths) to the top-level module they name, and prints the
graph "module -> dependencies". Comments, string literals and, unless --with-tests is given,
`#[cfg(test)]` items are ignored: the graph is the one the library itself compiles. Exits 1 and
prints each cycle if the graph has one, 0 otherwise. No dependencies beyond the standard library.
"""

import os
import re
import sys

IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def strip_comments_and_strings(text):
    """Blank out comments, string and char literals, keeping line structure and byte offsets."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:]) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r"r(#*)\"", text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            j = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'":
            # A char literal ('a', '\n', '\u{1F600}'), not a lifetime ('a).
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching_brace(text, open_at):
    depth = 0
    for j in range(open_at, len(text)):
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(text) - 1


CFG_TEST = re.compile(r"#\[cfg\(test\)\]")


def strip_test_items(text):
    """Blank out items under `#[cfg(test)]` (an inline module or block, or a `mod x;`)."""
    while True:
        m = CFG_TEST.search(text)
        if not m:
            return text
        j = m.end()
        semi = text.find(";", j)
        brace = text.find("{", j)
        if brace < 0 or (0 <= semi < brace):
            end = semi
        else:
            end = matching_brace(text, brace)
        text = text[: m.start()] + re.sub(r"[^\n]", " ", text[m.start() : end + 1]) + text[end + 1 :]


def test_only_files(src, texts):
    """Files declared by `#[cfg(test)] mod name;`: they compile into tests only."""
    skip = set()
    decl = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*mod\s+([A-Za-z_][A-Za-z0-9_]*)\s*;")
    for path, text in texts.items():
        base = os.path.dirname(path)
        stem = os.path.splitext(os.path.basename(path))[0]
        folder = base if stem in ("mod", "lib") else os.path.join(base, stem)
        for name in decl.findall(text):
            for cand in (os.path.join(folder, name + ".rs"), os.path.join(folder, name, "mod.rs")):
                skip.add(os.path.normpath(cand))
            # A file's `mod x;` may name a sibling through #[path]; rare enough to ignore.
    return skip


def module_path(src, path):
    rel = os.path.relpath(path, src)
    parts = rel[:-3].split(os.sep)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return parts


def group_heads(text, open_at):
    """First path segment of each entry of the brace group opening at `open_at`."""
    close = matching_brace(text, open_at)
    body = text[open_at + 1 : close]
    heads, depth, start = [], 0, 0
    for k, ch in enumerate(body + ","):
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif ch == "," and depth == 0:
            m = IDENT.search(body[start:k])
            if m:
                heads.append(m.group(0))
            start = k + 1
    return heads


PATH = re.compile(r"(?<![A-Za-z0-9_:])(crate|(?:super::)*super)::")


def references(text, mod_path):
    """Top-level modules that a file's code names."""
    found = set()
    for m in PATH.finditer(text):
        head = m.group(1)
        if head == "crate":
            base = []
        else:
            ups = head.count("super")
            # A `super::` inside an inline module (indented) starts one level deeper.
            line_start = text.rfind("\n", 0, m.start()) + 1
            inline = text[line_start : m.start()].strip() not in ("", "use", "pub use", "pub(crate) use")
            indented = text[line_start:m.start()] != text[line_start:m.start()].lstrip()
            depth = len(mod_path) + (1 if indented and not inline else 0)
            base = (mod_path + ["<inline>"])[: max(depth - ups, 0)]
        rest = text[m.end() :]
        if base:
            found.add(base[0])
            continue
        if rest.startswith("{"):
            found.update(group_heads(text, m.end()))
        else:
            ident = IDENT.match(rest)
            if ident:
                found.add(ident.group(0))
    return found


def build_graph(crate_dir, with_tests):
    src = os.path.join(crate_dir, "src")
    texts = {}
    for root, _, files in os.walk(src):
        for f in files:
            if f.endswith(".rs"):
                p = os.path.normpath(os.path.join(root, f))
                with open(p, encoding="utf-8") as fh:
                    texts[p] = strip_comments_and_strings(fh.read())
    skip = set() if with_tests else test_only_files(src, texts)
    modules = sorted({module_path(src, p)[0] for p in texts if module_path(src, p)})
    graph = {m: set() for m in modules}
    for path, text in texts.items():
        if path in skip:
            continue
        mp = module_path(src, path)
        if not mp:
            continue
        if not with_tests:
            text = strip_test_items(text)
        for target in references(text, mp):
            if target in graph and target != mp[0]:
                graph[mp[0]].add(target)
    return graph


def cycles(graph):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def layers(graph):
    """Modules by depth: 0 uses no sibling, n uses only modules below n."""
    depth = {}

    def d(v, seen=()):
        if v in depth:
            return depth[v]
        if v in seen:
            return 0
        depth[v] = 1 + max((d(w, seen + (v,)) for w in graph[v]), default=-1)
        return depth[v]

    for v in graph:
        d(v)
    return depth


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    if len(args) != 1:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    crate_dir = args[0]
    graph = build_graph(crate_dir, "--with-tests" in argv)
    name = os.path.basename(os.path.normpath(crate_dir))
    if "--mermaid" in argv:
        print("```mermaid")
        print("graph TD")
        for v in sorted(graph):
            if not graph[v]:
                print(f"    {v}")
            for w in sorted(graph[v]):
                print(f"    {v} --> {w}")
        print("```")
    else:
        depth = layers(graph)
        print(f"# {name}: top-level modules, lowest layer first (module -> what it uses)")
        for v in sorted(graph, key=lambda v: (depth[v], v)):
            deps = ", ".join(sorted(graph[v])) or "-"
            print(f"{depth[v]:>2} {v:<14} -> {deps}")
    found = cycles(graph)
    for comp in found:
        print(f"cycle: {' <-> '.join(comp)}", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
