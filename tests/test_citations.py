"""Every "§" citation in the package, the tests, the docs, the experiments, the benchmarks, the
studies and the README names a numbered section of a file that is in the repository
(docs/design.md, docs/kinova-facts.md, ...), so a reader who clones it never follows a
citation into a dead end.

A citation is ``FILE.md §N`` (also ``FILE.md's §N``, lists ``§6, §9``, ``§7 and §9`` and ranges
``§1–§7``, ``§3–4``), FILE a path from the repository root or from the citing file's folder.
A bare ``§N`` means the citing Markdown page's own section N when the page has numbered
sections, else the file cited last before it in the same file. A section N exists when the
file has a heading ``#… N. title``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SIGN = "\N{SECTION SIGN}"
NUMBER = rf"{SIGN}\s?(\d+)"
LIST = rf"{NUMBER}(?:\s*(?:[–-]|,|and|&)\s*{SIGN}?\s?\d+)*"
CITATION = re.compile(rf"(?P<file>[A-Za-z0-9_./-]+\.md)(?:'s)?\s+(?P<list>{LIST})")
SECTION = re.compile(NUMBER)
RANGE = re.compile(rf"{SIGN}?\s?(\d+)\s*[–-]\s*{SIGN}?\s?(\d+)")


def cited_sections(text: str) -> set[int]:
    """The section numbers of one citation list (``§1–§7`` gives 1 … 7)."""
    numbers = {int(n) for n in re.findall(r"\d+", text)}
    for low, high in RANGE.findall(text):
        numbers |= set(range(int(low), int(high) + 1))
    return numbers


def numbered_sections(path: Path) -> set[int]:
    """The N of every heading ``#… N. title`` of a Markdown file."""
    found = re.findall(r"^#+\s+(\d+)\.\s", path.read_text(encoding="utf-8"), flags=re.M)
    return {int(n) for n in found}


def resolve(name: str, citing: Path) -> Path | None:
    for base in (ROOT, citing.parent):
        candidate = (base / name).resolve()
        if candidate.is_file() and candidate.is_relative_to(ROOT):
            return candidate
    return None


def citing_files() -> list[Path]:
    files = [ROOT / "README.md"]
    for folder, suffixes in (
        ("pushctl", {".py", ".toml", ".md"}),
        ("tests", {".py", ".md", ".toml"}),
        ("docs", {".md"}),
        ("experiments", {".toml", ".md"}),
        ("benchmarks", {".py", ".md"}),
        ("studies", {".py", ".md"}),
    ):
        files += [p for p in sorted((ROOT / folder).rglob("*")) if p.suffix in suffixes]
    return [p for p in files if p.resolve() != Path(__file__).resolve()]


def citation_problems(path: Path, text: str | None = None) -> list[str]:
    """One line per citation of ``path`` (its ``text``, default the file's) that does not
    resolve."""
    text = path.read_text(encoding="utf-8") if text is None else text
    where = path.relative_to(ROOT)
    own = set(re.findall(r"^#+\s+(\d+)\.\s", text, flags=re.M)) if path.suffix == ".md" else set()
    own = {int(n) for n in own}
    problems: list[str] = []
    covered: list[tuple[int, int]] = []
    cited = sorted(CITATION.finditer(text), key=lambda m: m.start())
    for match in cited:
        covered.append(match.span("list"))
        target = resolve(match["file"], path)
        line = text.count("\n", 0, match.start()) + 1
        if target is None:
            problems.append(f"{where}:{line}: {match['file']} is not in the repository")
            continue
        missing = cited_sections(match["list"]) - numbered_sections(target)
        if missing:
            problems.append(f"{where}:{line}: {match['file']} has no section {sorted(missing)}")
    for match in SECTION.finditer(text):
        if any(start <= match.start() < end for start, end in covered):
            continue
        line = text.count("\n", 0, match.start()) + 1
        number = int(match.group(1))
        before = [m for m in cited if m.start() < match.start()]
        last = resolve(before[-1]["file"], path) if before else None
        if own:
            if number not in own:
                problems.append(f"{where}:{line}: this page has no section {number}")
        elif last is None:
            problems.append(f"{where}:{line}: §{number} names no file")
        elif number not in numbered_sections(last):
            problems.append(f"{where}:{line}: {last.name} has no section {number}")
    return problems


def test_every_section_citation_resolves_to_a_file_in_the_repository() -> None:
    files = citing_files()
    assert len(files) > 50
    problems = [problem for path in files for problem in citation_problems(path)]
    assert not problems, "\n".join(problems)


def test_the_design_page_keeps_its_numbered_sections() -> None:
    assert numbered_sections(ROOT / "docs" / "design.md") == set(range(1, 10))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("see docs/design.md §5.", []),
        ("docs/design.md §6, §9 and then §7", []),
        ("docs/kinova-facts.md §1–§7", []),
        ("docs/design.md §3–4", []),
        ("docs/design.md §12", ["has no section [12]"]),
        ("DESIGN.md §5", ["is not in the repository"]),
        ("a bare §5 in code", ["names no file"]),
        ("docs/design.md §5, then docs/design.md's §10", ["has no section [10]"]),
    ],
)
def test_the_checker_tells_good_citations_from_dead_ends(text: str, expected: list[str]) -> None:
    problems = citation_problems(ROOT / "tests" / "probe.py", text)
    assert len(problems) == len(expected)
    for problem, fragment in zip(problems, expected, strict=True):
        assert fragment in problem
