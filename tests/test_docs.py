"""The repository explains itself: nothing points to documents outside it."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTSIDE = re.compile(r"(?<![\w/])(MODEL|STUDIES|RECOVERY)\.md|shared/spec|shared/paper")
LINK = re.compile(r"\]\([A-Z_]+\.md(#[\w-]*)?\)")  # a link between the docs/ pages themselves


def _tracked() -> list[Path]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:  # not a git checkout (an sdist): every text file
        return [p for p in ROOT.rglob("*") if p.suffix in (".py", ".md", ".toml", ".html")]
    return [ROOT / f for f in out.stdout.split() if f.endswith((".py", ".md", ".toml", ".html"))]


def test_no_reference_to_documents_outside_the_repository():
    hits = []
    for path in _tracked():
        if path.name == "test_docs.py":
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines()):
            if path.parent.name == "docs":
                line = LINK.sub("]()", line)
            if OUTSIDE.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{n + 1}: {line.strip()}")
    assert not hits, "\n".join(hits)


def test_the_docs_it_points_to_exist():
    missing = []
    for path in _tracked():
        text = path.read_text(encoding="utf-8", errors="replace")
        for name in set(re.findall(r"docs/([A-Z_]+\.md)", text)):
            if not (ROOT / "docs" / name).is_file():
                missing.append(f"{path.relative_to(ROOT)} -> docs/{name}")
    assert not missing, "\n".join(missing)
