#!/usr/bin/env python3
"""Writes every C++ block of the given Markdown files out as translation units that compile
against the installed package, and every C block as a C11 program that links against it (the
C API): tests/install/run_consumer.cmake builds them, so code the docs show is code that
compiles.

Usage: scripts/doc_snippets.py OUT_DIR FILE.md...

Rules (what a reader assumes anyway):
- A ```cpp or ```c++ block is a snippet. A ```c block is a whole C program (it must define
  `int main(`), written as it is to a .c file of its own. Other languages (```sh, ```cmake,
  ```text) are not snippets.
- A block that defines `int main(` is a whole file of its own.
- The other blocks of one Markdown file continue each other, in order, as the body of one
  function, so a later block may use what an earlier one declared, as the reader reads them.
- `#include` lines are hoisted to the top of the file; every file includes <detsim/detsim.hpp>.
- Names a block uses that the page never defines (a game's own `render()`, the `session` of an
  earlier page) are declared at file scope in an HTML comment right before the block, hidden
  when the Markdown is rendered:
      <!-- snippet context
      void render(const detsim::World& world);
      -->
  The units are compiled, never linked or run, so declarations are enough.
- `#line` directives point every compiler message at the Markdown file and line.

Exits 1, naming the file and line, on a block that is never closed; prints how many snippets it
wrote.
"""
import os
import pathlib
import re
import sys

FENCE = re.compile(r"^```\s*(\S*)")
CONTEXT_OPEN = "<!-- snippet context"


def parse(path, languages=("cpp", "c++")):
    """[(first line number of the code, code lines, context lines)] of the blocks in
    `languages` (the C++ blocks by default)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        language = m.group(1).lower()
        start = i
        i += 1
        while i < len(lines) and not lines[i].startswith("```"):
            i += 1
        if i == len(lines):
            sys.exit(f"{path}:{start + 1}: a ``` block that is never closed")
        if language in languages:
            blocks.append((start + 2, lines[start + 1:i], context_before(lines, start)))
        i += 1
    return blocks


def context_before(lines, fence):
    """The declarations of a `<!-- snippet context ... -->` comment ending right before the
    fence (blank lines between are allowed), else []."""
    end = fence - 1
    while end >= 0 and not lines[end].strip():
        end -= 1
    if end < 0 or lines[end].strip() != "-->":
        return []
    begin = end - 1
    while begin >= 0 and lines[begin].strip() != CONTEXT_OPEN:
        if lines[begin].strip().startswith("<!--"):
            return []
        begin -= 1
    if begin < 0:
        return []
    return [(begin + 2, lines[begin + 1:end])]


def unit(source, blocks, wrap, name):
    """The text of one translation unit of `blocks` from Markdown file `source`."""
    includes = ["#include <detsim/detsim.hpp>"]
    file_scope = []
    body = []
    for first, code, contexts in blocks:
        for at, declarations in contexts:
            file_scope.append(f'#line {at} "{source}"')
            file_scope.extend(declarations)
        kept = []
        for offset, line in enumerate(code):
            if line.lstrip().startswith("#include"):
                includes.append(line.strip())
                kept.append("")  # keeps the line numbers
            else:
                kept.append(line)
        (body if wrap else file_scope).append(f'#line {first} "{source}"')
        (body if wrap else file_scope).extend(kept)
    out = list(dict.fromkeys(includes)) + [""] + file_scope
    if wrap:
        out += ["", f"[[maybe_unused]] int {name}() {{"] + body + ["  return 0;", "}"]
    return "\n".join(out) + "\n"


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: scripts/doc_snippets.py OUT_DIR FILE.md...")
    out_dir = pathlib.Path(sys.argv[1])
    out_dir.mkdir(parents=True, exist_ok=True)
    for old in [*out_dir.glob("*.cpp"), *out_dir.glob("*.c")]:
        old.unlink()
    written = 0
    c_programs = 0
    pages = [pathlib.Path(arg).resolve() for arg in sys.argv[2:]]
    root = pathlib.Path(os.path.commonpath([p.parent for p in pages]))
    for path in pages:
        stem = re.sub(r"[^A-Za-z0-9]", "_", str(path.relative_to(root).with_suffix("")))
        source = path.as_posix()
        continuing = []
        for index, block in enumerate(parse(path)):
            if any("int main(" in line for line in block[1]):
                (out_dir / f"{stem}_{index}.cpp").write_text(unit(source, [block], False, ""))
            else:
                continuing.append(block)
            written += 1
        if continuing:
            (out_dir / f"{stem}.cpp").write_text(
                unit(source, continuing, True, f"doc_snippets_{stem}"))
        for index, (first, code, _) in enumerate(parse(path, ("c",))):
            if not any("int main(" in line for line in code):
                sys.exit(f"{path}:{first}: a C block must be a whole program (int main)")
            text = "\n".join([f'#line {first} "{source}"'] + code) + "\n"
            (out_dir / f"{stem}_c{index}.c").write_text(text)
            c_programs += 1
    print(f"doc_snippets: {written} C++ blocks and {c_programs} C programs from "
          f"{len(sys.argv) - 2} files")


if __name__ == "__main__":
    main()
