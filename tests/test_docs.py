"""The README and docs/ stay documents for users: short pages, every page reachable from
docs/index.md, every relative link resolving, no commit hashes, issue numbers or
development-pass narratives, and a command-line reference that names exactly the options the
commands have."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import typer.main

from pushctl.cli import app

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
INDEX = DOCS / "index.md"
OTHER_WRITERS = {DOCS / "performance.md", DOCS / "realdata.md"}
"""Pages written by tools or other parts of the project (`make bench` writes the performance
page): links to them are allowed before they exist, and their format is theirs."""
MAX_PAGE_LINES = 400
MAX_README_LINES = 150

FENCE = re.compile(r"^```.*?^```", flags=re.S | re.M)
LINK = re.compile(r"(?<!!)\[[^\]]*\]\((?P<target>[^)\s]+)\)")
IMAGE = re.compile(r"!\[[^\]]*\]\((?P<target>[^)\s]+)\)")
DOCS_PATH = re.compile(r"(?<![\w/.-])docs/[\w/.-]+\.md\b")
COMMIT_HASH = re.compile(
    r"(?<![\w.+-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![\w+-])"
)
ORDINALS = (
    "first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth|"
    r"\w+teenth|twentieth|twenty-\w+|thirtieth|thirty-\w+|\d+(?:st|nd|rd|th)"
)
PASS_NARRATIVE = re.compile(rf"\b(?:{ORDINALS})\s+pass\b", flags=re.I)
ISSUE_NUMBER = re.compile(r"\bissues?\s+#?\d+", flags=re.I)


def pages() -> list[Path]:
    """Every Markdown page of docs/ (the ones other tools write included)."""
    return sorted(DOCS.rglob("*.md"))


def own_pages() -> list[Path]:
    return [page for page in pages() if page not in OTHER_WRITERS]


def prose(text: str) -> str:
    """``text`` without its fenced code blocks (digests, command output)."""
    return FENCE.sub("", text)


def relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def test_pages_are_short() -> None:
    assert len(README.read_text().splitlines()) <= MAX_README_LINES
    long = {
        relative(p): n for p in pages() if (n := len(p.read_text().splitlines())) > MAX_PAGE_LINES
    }
    assert long == {}, f"pages over {MAX_PAGE_LINES} lines"


def test_every_page_starts_with_what_it_answers() -> None:
    for page in own_pages():
        lines = page.read_text().splitlines()
        assert lines and lines[0].startswith("# "), relative(page)
        assert any("This page answers" in line for line in lines[:6]), relative(page)


def history_problems(text: str) -> list[str]:
    """Commit hashes, issue numbers and "Nth pass" narratives in ``text``'s prose."""
    body = prose(text)
    found = [f"commit hash {m.group()!r}" for m in COMMIT_HASH.finditer(body)]
    found += [f"pass narrative {m.group()!r}" for m in PASS_NARRATIVE.finditer(body)]
    found += [f"issue number {m.group()!r}" for m in ISSUE_NUMBER.finditer(body)]
    return found


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("made at ce01a60, 59 min", 1),
        ("see commit 4d80d3e9f2a1", 1),
        ("the twenty-fourth pass measured", 1),
        ("### Sixth pass: a threshold", 1),
        ("the 12th pass", 1),
        ("On issue 16's acceptance", 1),
        ("inertia 7.8999684e-07 and 1.2e-3", 0),
        ("a seed of 104106432, an effaced decade", 0),
        ("```\nsha256 0a8d5ef18a86d643\n```", 0),
        ("the first push, a pass of the law, bypass", 0),
    ],
)
def test_the_history_check_tells_history_from_facts(text: str, expected: int) -> None:
    assert len(history_problems(text)) == expected


def test_no_page_carries_development_history() -> None:
    problems = {
        relative(page): found
        for page in [README, *own_pages()]
        if (found := history_problems(page.read_text()))
    }
    assert problems == {}


def link_problems(page: Path, text: str | None = None) -> list[str]:
    """Relative links and images of ``page`` (its ``text``, default the file's), and the
    ``docs/…md`` paths its prose names, that lead to no file."""
    text = prose(page.read_text() if text is None else text)
    problems = []
    targets = [m["target"] for m in (*LINK.finditer(text), *IMAGE.finditer(text))]
    for target in targets:
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # a web address, or a heading of this page
        path = (page.parent / target.split("#")[0]).resolve()
        if not path.exists() and path not in OTHER_WRITERS:
            problems.append(target)
    for named in DOCS_PATH.findall(text):
        path = (ROOT / named).resolve()
        if not path.exists() and path not in OTHER_WRITERS:
            problems.append(named)
    return problems


def test_every_relative_link_resolves() -> None:
    problems = {
        relative(page): found for page in [README, *own_pages()] if (found := link_problems(page))
    }
    assert problems == {}


def test_the_link_check_finds_a_dead_link() -> None:
    page = DOCS / "howto" / "probe.md"
    text = "[gone](../gone.md), [there](../index.md), docs/nowhere.md, docs/index.md\n"
    text += "[a page to come](../performance.md), [web](https://example.org/x.md)\n"
    assert link_problems(page, text) == ["../gone.md", "docs/nowhere.md"]


def test_the_readme_leads_to_the_index_and_the_index_to_every_page() -> None:
    assert "](docs/index.md)" in README.read_text()
    text = INDEX.read_text()
    linked = {(DOCS / m["target"].split("#")[0]).resolve() for m in LINK.finditer(text)}
    missing = [relative(p) for p in pages() if p != INDEX and p.resolve() not in linked]
    assert missing == [], "docs/index.md does not list these pages"
    for page in OTHER_WRITERS:
        assert page.resolve() in linked, relative(page)


def test_the_repository_says_how_to_cite_and_license_it() -> None:
    import yaml

    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors", "license"):
        assert citation[key], key
    paper = citation["preferred-citation"]
    assert paper["title"].startswith("Hybrid Contact Dynamics and Residual-RL Framework")
    assert [a["family-names"] for a in paper["authors"]] == ["Chen", "Dai", "Kövecses"]
    assert paper in citation["references"]
    assert (ROOT / "LICENSE").read_text().startswith("BSD 3-Clause License")
    assert citation["license"] == "BSD-3-Clause"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in changelog and "\n## [0.1.0]" in changelog


def documented_options() -> dict[str, set[str]]:
    """Each ``## `pushctl NAME` `` section of docs/reference/cli.md → the options it names."""
    text = (DOCS / "reference" / "cli.md").read_text()
    sections = re.split(r"^## `pushctl ([a-z-]+(?: [a-z-]+)?)[^`]*`$", text, flags=re.M)
    return {
        name: set(re.findall(r"`(--[a-z][a-z0-9-]*)`", body))
        for name, body in zip(sections[1::2], sections[2::2], strict=True)
    }


def test_the_cli_reference_names_every_option_and_no_other() -> None:
    groups = typer.main.get_command(app).commands  # type: ignore[attr-defined]
    commands = {}
    for name, command in groups.items():  # a sub-app's commands as "group command"
        subcommands = getattr(command, "commands", None)
        if subcommands:
            commands.update({f"{name} {sub}": c for sub, c in subcommands.items()})
        else:
            commands[name] = command
    documented = documented_options()
    assert set(documented) == set(commands), "a command without a section, or the reverse"
    for name, command in commands.items():
        options = {opt for p in command.params for opt in p.opts if opt.startswith("--")}
        assert documented[name] == options - {"--help"}, name
