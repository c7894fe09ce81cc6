"""The repository explains itself: nothing points to documents outside it, and its prose
reads aloud."""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass
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
    return sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "README.md", ROOT / "benchmarks" /
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
                    "quadimpact benchmark ", "quadimpact train "):  # fmt: skip
        assert command in head, command


def test_readme_images_exist():
    """Every picture the README shows is a file of the repository."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    images = re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", text) + re.findall(r'<img src="([^"]+)"', text)
    assert images, "the README shows no picture"
    missing = [image for image in images if not (ROOT / image).is_file()]
    assert not missing, missing


# ------------------------------------------------- issue 60 item 2: sentences to read aloud
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
MD_TARGET = re.compile(r"(!?)\[([^\]]*)\]\([^)]*\)")
LIST_MARKER = re.compile(r"^\s*(?:[-*+]|\d+[.)])\s+")
QUOTE = re.compile(r"^\s*>\s?")
ABBREVIATIONS = ("e.g.", "i.e.", "et al.", "vs.", "cf.", "etc.", "Fig.", "Eq.", "No.")
SENTENCE_END = re.compile(r"(?<=[.!?])[\"')\]*_]*\s+")
HAS_WORD = re.compile(r"[^\W_]")  # a letter or a digit
MEAN_WORDS, MAX_WORDS = 20, 50


@dataclass(frozen=True)
class Sentence:
    """One sentence of prose: the line it starts on (1-based), its words, its text."""

    line: int
    words: int
    text: str


def _prose_units(text: str):
    """Yield (first line, text) of each paragraph and each list item of a Markdown text,
    code blocks, tables, headings, HTML comments and lone pictures aside."""
    unit: list[str] = []
    start, fenced = 0, False
    for n, raw in enumerate(text.splitlines(), 1):
        item = bool(LIST_MARKER.match(raw)) and not fenced
        stripped = raw.strip()
        if (
            FENCE.match(raw)
            or fenced
            or item
            or not stripped
            or stripped.startswith(("#", "|", "<!--", "!["))
        ):
            if unit:
                yield start, " ".join(unit)
                unit = []
            if FENCE.match(raw):
                fenced = not fenced
            if not item:
                continue
        if not unit:
            start = n
        unit.append(LIST_MARKER.sub("", QUOTE.sub("", raw)).strip())
    if unit:
        yield start, " ".join(unit)


def sentences(text: str) -> list[Sentence]:
    """The sentences of the prose of a Markdown text.

    Prose is every paragraph and every list item (its marker and a quote's ``>`` aside);
    fenced code blocks, tables (lines starting ``|``), headings, HTML comments and lines
    holding only a picture are not prose. In prose an inline code span counts as one word
    and a link or picture counts as its text (its target aside).

    A *sentence* ends at ``.``, ``!`` or ``?`` followed by white space (closing quotes,
    brackets and emphasis marks in between), or at the end of its paragraph or list item;
    the abbreviations of ``ABBREVIATIONS`` end none. A *word* is a run of non-space
    characters that holds a letter or a digit (so ``—`` and ``=`` are not words, ``3.5``
    and ``100-Hz`` are one each).
    """
    out = []
    for line, unit in _prose_units(text):
        unit = CODE_SPAN.sub("CODE", unit)
        unit = MD_TARGET.sub(r"\2", unit)
        for abbreviation in ABBREVIATIONS:
            unit = unit.replace(abbreviation, abbreviation.replace(".", ""))
        for piece in SENTENCE_END.split(unit):
            words = sum(1 for word in piece.split() if HAS_WORD.search(word))
            if words:
                out.append(Sentence(line, words, piece.strip()))
    return out


def _prose_pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def test_sentence_counter_on_a_sample():
    """The counter counts what its docstring says: code, tables, headings and link targets
    aside; list items and paragraphs end sentences; a code span is one word."""
    sample = "\n".join([
        "# A heading of many words that is not prose at all",
        "",
        "One two three. Four five, e.g. six",
        "seven eight (`a. b c d` is one word)!",
        "",
        "```",
        "code is not. prose at all here",
        "```",
        "",
        "| a table | is not prose either. |",
        "- a list item [with a link](very/long/target/words.md) ends",
        "- 3.5 m/s = fast",
        "",
        "> quoted words count too",
    ])  # fmt: skip
    found = [(s.line, s.words) for s in sentences(sample)]
    assert found == [(3, 3), (3, 10), (11, 7), (12, 3), (14, 4)], found


def test_the_prose_reads_aloud():
    """README.md and docs/**/*.md: the mean sentence is at most 20 words and none is over
    50 (issue 60: it was 25.9 words, and 215 sentences were over 50)."""
    all_sentences, long = [], []
    for page in _prose_pages():
        for sentence in sentences(page.read_text(encoding="utf-8")):
            all_sentences.append(sentence)
            if sentence.words > MAX_WORDS:
                name = page.relative_to(ROOT)
                long.append(f"{name}:{sentence.line}: ({sentence.words} words) {sentence.text}")
    mean = sum(s.words for s in all_sentences) / len(all_sentences)
    assert not long, f"{len(long)} sentences over {MAX_WORDS} words:\n" + "\n".join(long)
    assert mean <= MEAN_WORDS, f"the mean sentence is {mean:.1f} words, over {MEAN_WORDS}"


def test_the_readaloud_check_can_fail():
    """A sentence of 51 words is reported with its file and line; a text of long sentences
    has a mean over 20."""
    long = " ".join(["word"] * 51) + "."
    found = sentences("Short one.\n\n" + long)
    assert [(s.line, s.words) for s in found] == [(1, 2), (3, 51)]
    assert sum(s.words for s in found) / len(found) > MEAN_WORDS


# ------------------------------------------------- issue 60 item 2: paths that exist
PATH = re.compile(r"(?<![\w./-])((?:[\w.-]+/)+[\w.-]+\.(?:py|toml|md|csv|png|npz|json|html))\b")
#: Where a path the docs name may start: the repository, the package and its core.
PATH_ROOTS = ("", "src", "src/quadimpact", "src/quadimpact/core", "docs")
#: Paths that name a user's output or a placeholder, not a file of the repository.
PLACEHOLDERS = ("DIR/", "results/", "path/", "plots/", "my_", "../")


def test_every_path_the_docs_name_exists():
    """A path like ``core/contact.py`` in README.md or docs/**/*.md is a file of the
    repository (docs/ARCHITECTURE.md named a ``geometry/record.py`` that had moved)."""
    stale = []
    for page in _prose_pages():
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            for path in PATH.findall(line):
                if path.startswith(PLACEHOLDERS):
                    continue
                bases = [ROOT / root for root in PATH_ROOTS] + [page.parent]
                if not any((base / path).exists() for base in bases):
                    stale.append(f"{page.relative_to(ROOT)}:{n}: {path}")
    assert not stale, "\n".join(stale)


def test_sections_are_numbered_in_order():
    """The numbered headings of each page count 1, 2, 3, ... and 2.1, 2.2, ... under
    each (a page once had two sections 4)."""
    bad = []
    for page in _prose_pages():
        last: list[int] = []
        fenced = False
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if FENCE.match(line):
                fenced = not fenced
            match = re.match(r"#+ (\d+(?:\.\d+)*)\.? ", line)
            if fenced or not match:
                continue
            number = [int(x) for x in match.group(1).split(".")]
            expected = last[: len(number) - 1] + [1]
            if len(number) <= len(last):
                expected = last[: len(number) - 1] + [last[len(number) - 1] + 1]
            if number != expected:
                bad.append(f"{page.relative_to(ROOT)}:{n}: {line} (expected {expected})")
            last = number
    assert not bad, "\n".join(bad)


def test_the_index_lists_every_page():
    """docs/README.md lists every page of docs/ under its purpose (tutorial, how-to,
    reference, explanation), and the README points to it."""
    index = (ROOT / "docs" / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"\]\(([\w/-]+\.md)\)", index))
    pages = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    missing = sorted(pages - listed - {"README.md"})
    assert not missing, f"docs/README.md does not list {missing}"
    headings = re.findall(r"^## (\w+)", index, flags=re.M)
    assert headings == ["Tutorial", "How", "Reference", "Explanation"], headings
    assert "docs/README.md" in (ROOT / "README.md").read_text(encoding="utf-8")


COMMAND = re.compile(r"quadimpact ([a-z]+)((?:\s+[^`|;&\n]*)?)")


def _misplaced_flags(text: str, options: dict[str, set[str]]) -> list[tuple[int, str]]:
    """(line, "command --flag") of each flag given to a quadimpact command that lacks it."""
    found = []
    for n, line in enumerate(text.splitlines(), 1):
        for match in COMMAND.finditer(line):
            command = match.group(1)
            if command in options:
                found += [(n, f"quadimpact {command} {flag}")
                          for flag in FLAG.findall(match.group(2))
                          if flag not in options[command]]  # fmt: skip
    return found


def test_each_command_in_the_docs_has_the_flags_given_to_it():
    """A command line of the docs gives each quadimpact command only its own options
    (docs/howto once gave ``quadimpact sweep`` a ``--model`` that only ``run`` has)."""
    from quadimpact.cli import cli

    options = {
        name: {"--help", *(o for p in command.params for o in (*p.opts, *p.secondary_opts))}
        for name, command in cli.commands.items()
    }
    sample = "`quadimpact sweep --grid model=paper-replica --model paper-replica --out x`"
    assert _misplaced_flags(sample, options) == [(1, "quadimpact sweep --model")]
    bad = []
    for page in _doc_pages():
        for n, flag in _misplaced_flags(page.read_text(encoding="utf-8"), options):
            bad.append(f"{page.relative_to(ROOT)}:{n}: {flag}")
    assert not bad, "\n".join(bad)
