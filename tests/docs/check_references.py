#!/usr/bin/env python3
"""Every reference a reader follows leads somewhere (docs.references).

A newcomer meets the documentation through links, through paths named in the text, and
through the messages and `--help` of the programs, which name a page and often a section.
A reference that leads nowhere is a dead end for the one reader who followed it. Checked:

1. Markdown links between the project's pages: the file exists, and an anchor
   (`page.md#section`) is one of that page's headings (GitHub's rule for anchors).
2. Paths written in backticks in a page (`tests/data/scenes/minimal.yaml`,
   `dem/engine/canonical_order.*`): a file or folder of the repository (a `*` or `<...>`
   part matches anything; an `N`/`NNN` placeholder and paths a program writes are not files).
3. Pages named in the sources (`docs/stability.md` in a message or a comment): the file
   exists; with a section (`docs/stability.md, "The overlap guard"`), a heading of that page
   or a paragraph's bold title (`**Starting fields.**`) begins with it, or contains it after
   a colon ("hindered settling" is "Measured: hindered settling in a periodic box").
4. An example a page says is a file of the repository (a fenced block followed by "This is
   `tests/data/scenes/minimal.yaml`") is that file, apart from comment lines: a reader who
   copies the example runs what the tests run.

Usage: check_references.py SOURCE_DIR
"""
import glob
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
SKIP_DIRS = {".git", "build", "node_modules"}
TOP = ("dem/", "coupling/", "foam_solver/", "tests/", "tutorials/", "benchmarks/", "docs/",
       "scripts/", "cmake/", ".ci/")


def files(patterns):
    out = []
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build")]
        for name in filenames:
            if any(name.endswith(p) for p in patterns):
                out.append(os.path.join(dirpath, name))
    return sorted(out)


def slug(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    h = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return h.replace(" ", "-")


_headings = {}


def headings(path):
    """(anchors, heading texts) of a Markdown page, outside code fences."""
    if path not in _headings:
        anchors, texts, seen, fence = set(), [], {}, False
        for line in open(path, encoding="utf-8"):
            if line.startswith("```"):
                fence = not fence
            bold = None if fence else re.match(r"^(?:- )?\*\*([^*]+?)[.:]?\*\*", line)
            if bold:  # a paragraph's bold title is a section too
                texts.append(bold.group(1))
            m = None if fence else re.match(r"^#+\s+(.*?)\s*$", line)
            if m:
                texts.append(m.group(1))
                a = slug(m.group(1))
                n = seen.get(a, -1) + 1
                seen[a] = n
                anchors.add(a if n == 0 else f"{a}-{n}")
        _headings[path] = (anchors, texts)
    return _headings[path]


def without_code_blocks(text):
    return re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)


def path_exists(p):
    """A repository path, where `*` and `<...>` match anything."""
    p = p.rstrip("/.,;:")
    if os.path.exists(os.path.join(ROOT, p)) or glob.glob(os.path.join(ROOT, p) + ".*"):
        return True  # a file, or a source named without its extension
    if re.search(r"[*<{]", p):
        pattern = re.sub(r"<[^>]*>", "*", p)
        pattern = re.sub(r"\{[^}]*\}", "*", pattern)
        return bool(glob.glob(os.path.join(ROOT, pattern)))
    return os.path.exists(os.path.join(ROOT, p))


problems = []


def report(where, what):
    problems.append(f"{os.path.relpath(where, ROOT)}: {what}")


pages = files([".md"])
for page in pages:
    text = open(page, encoding="utf-8").read()
    prose = without_code_blocks(text)
    # 1. Links.
    for m in re.finditer(r"\]\(([^)\s]+)\)", prose):
        target = m.group(1)
        if re.match(r"^[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        dest = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
        if not os.path.exists(dest):
            report(page, f"link ({target}): no file {os.path.relpath(dest, ROOT)}")
        elif anchor and dest.endswith(".md") and anchor not in headings(dest)[0]:
            report(page, f"link ({target}): {os.path.relpath(dest, ROOT)} has no heading "
                   f"with the anchor #{anchor}")
    # 2. Paths in backticks.
    for m in re.finditer(r"`([^`\s]+)`", prose):
        p = m.group(1)
        if not p.startswith(TOP) or re.search(r"N{3,}|NN|_N\b", p) or "/output/" in p:
            continue  # placeholders, and the folders benchmarks write
        if "/" not in p.rstrip("/"):
            continue
        if not path_exists(p):
            report(page, f"`{p}` names no file or folder of the repository")

    # 4. Examples that are files.
    for m in re.finditer(r"^```[a-z]*\n((?:[^`]|`(?!``))*?)^```\n\s*This is `([^`]+)`", text, flags=re.S | re.M):
        shown, path = m.group(1), m.group(2)
        full = os.path.join(ROOT, path)
        if not os.path.isfile(full):
            report(page, f"the example said to be `{path}`: no such file")
            continue

        def body(t):
            return [l.rstrip() for l in t.splitlines() if l.strip() and not l.lstrip().startswith("#")]

        if body(shown) != body(open(full, encoding="utf-8").read()):
            report(page, f"the example said to be `{path}` differs from that file")

# 3. Pages named in the sources.
sources = files([".cpp", ".hpp", ".C", ".H", ".py", ".sh", ".cmake", "Allrun"])
page_ref = re.compile(r"\b((?:docs/)?(?:models/|theory/)?[a-z][a-z0-9-]*\.md)"
                      r",\s*(?:\\?\")(?P<section>[^\"\\]{3,80})")
for src in sources:
    if os.path.abspath(src) == os.path.abspath(__file__):
        continue
    text = open(src, encoding="utf-8", errors="replace").read()
    for m in re.finditer(r"\b(docs/[A-Za-z0-9_./-]+\.md)", text):
        if not os.path.exists(os.path.join(ROOT, m.group(1))):
            line = text.count("\n", 0, m.start()) + 1
            report(src, f"line {line}: {m.group(1)} does not exist")
    for m in page_ref.finditer(text):
        name = m.group(1)
        path = name if name.startswith("docs/") else None
        if path is None:  # a page named without docs/: find it under docs/
            found = [p for p in pages if p.endswith("/" + name) and "/docs/" in p]
            if len(found) != 1:
                continue
            path = os.path.relpath(found[0], ROOT)
        full = os.path.join(ROOT, path)
        if not os.path.exists(full):
            continue  # reported above
        section = re.sub(r"\s+", " ", m.group("section")).strip()
        # The section is quoted up to a line break in a comment: compare what fits.
        section = re.split(r"\s*(?://|#)\s*", section)[0].strip().rstrip(",.;:)")
        if len(section) < 3:
            continue
        texts = [re.sub(r"`", "", t).lower() for t in headings(full)[1]]
        want = section.replace("`", "").lower()
        def names(t):
            return t.startswith(want) or want.startswith(t) or \
                any(part.strip().startswith(want) for part in t.split(":")[1:])
        if not any(names(t) for t in texts):
            line = text.count("\n", 0, m.start()) + 1
            report(src, f"line {line}: {path} has no section \"{section}\"")

for p in problems:
    print(p)
print(f"{len(pages)} pages, {len(sources)} sources checked: {len(problems)} dead reference(s)")
sys.exit(1 if problems else 0)
