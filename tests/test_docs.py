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


# ------------------------------------------------- issue 20 item 14: flags and links
#: Flags of other programs that the docs name (not quadimpact's).
OTHER_PROGRAMS_FLAGS = {"--preload", "--check", "--port", "--nworkers", "--nthreads"}
# dask worker --preload --nworkers --nthreads; dask scheduler --port; ruff format --check
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
MD_LINK = re.compile(r"\]\(([^)\s]+)\)")


def _doc_pages() -> list[Path]:
    return sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md", ROOT / "benchmarks" /
                                                      "README.md"]  # fmt: skip


def _script_flags() -> set[str]:
    """The flags of the scripts in examples/ and benchmarks/ (their argparse options)."""
    flags: set[str] = set()
    for path in [*ROOT.glob("examples/*.py"), *ROOT.glob("benchmarks/*.py")]:
        text = path.read_text(encoding="utf-8")
        flags.update(re.findall(r"add_argument\(\s*\"(--[a-z][a-z0-9-]*)\"", text))
    return flags


def test_every_flag_the_docs_name_exists():
    """A flag named in docs/*.md or a README is an option of a quadimpact command (or of
    a script of examples/ or benchmarks/): docs/RECOVERY.md once named a --param that
    did not exist."""
    from quadimpact.cli import cli

    known = {"--help", "--version", *OTHER_PROGRAMS_FLAGS, *_script_flags()}
    for command in cli.commands.values():
        for param in command.params:
            known.update(o for o in (*param.opts, *param.secondary_opts) if o.startswith("--"))
    unknown = []
    for page in _doc_pages():
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines()):
            unknown += [f"{page.relative_to(ROOT)}:{n + 1}: {flag}"
                        for flag in FLAG.findall(line) if flag not in known]  # fmt: skip
    assert not unknown, "\n".join(unknown)


def test_every_relative_link_resolves():
    """Every relative link of docs/*.md and the READMEs points to a file of the repository
    (docs/LEARNING.md once linked docs/docs/RECOVERY.md)."""
    broken = []
    for page in _doc_pages():
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines()):
            for target in MD_LINK.findall(line):
                if re.match(r"[a-z]+:", target) or target.startswith("#"):
                    continue  # a URL or an anchor on the same page
                path = target.split("#")[0]
                if path and not (page.parent / path).exists():
                    broken.append(f"{page.relative_to(ROOT)}:{n + 1}: {target}")
    assert not broken, "\n".join(broken)


def test_no_tracked_symlink_points_outside_the_repository():
    """Issue 20 item 17: the repository tracked .venv-int, a link to another checkout's venv."""
    out = subprocess.run(["git", "ls-files", "-s"], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:  # not a git checkout
        return
    links = [line.split("\t", 1)[1] for line in out.stdout.splitlines()
             if line.startswith("120000 ")]  # fmt: skip
    bad = []
    for name in links:
        target = (ROOT / name).resolve()
        if not target.exists() or ROOT not in target.parents:
            bad.append(name)
    assert not bad, bad


# ------------------------------------------------- issue 60 item 1: a short README
def test_readme_is_short_and_opens_with_make_run_and_make_test():
    """The README is at most 150 lines, and its first two commands are the two that do
    everything on a fresh machine: ``make run``, then ``make test`` (what CI runs)."""
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines, more than 150"
    start = lines.index("```sh")  # the first block of commands
    commands = []
    for line in lines[start + 1 :]:
        if line.startswith("```"):
            break
        if line.split("#")[0].strip():
            commands.append(line.split("#")[0].strip())
    assert commands[:2] == ["make run", "make test"], commands
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert "make test" in ci, "the README's test command is no longer what CI runs"


def test_readme_names_each_first_task_within_its_first_screen():
    """Issue 60: within its first screen (60 lines) the README says what quadimpact is
    and gives the command of each first task."""
    head = "\n".join((ROOT / "README.md").read_text(encoding="utf-8").splitlines()[:60])
    assert "quadimpact simulates" in head
    for command in ("quadimpact run ", "quadimpact sweep ", "quadimpact recovery ",
                    "quadimpact benchmark ", "benchmarks/train_policy.py"):  # fmt: skip
        assert command in head, command


def test_readme_images_exist():
    """Every picture the README shows is a file of the repository."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    images = re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", text) + re.findall(r'<img src="([^"]+)"', text)
    assert images, "the README shows no picture"
    missing = [image for image in images if not (ROOT / image).is_file()]
    assert not missing, missing
