"""The documentation holds together: every relative link and picture of README.md and docs/
points at a file of the repository, and every bench/ and tools/ script has its line in
docs/architecture.md."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# [text](target) and ![alt](target); the target ends at the first space or closing parenthesis
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)[^)]*\)")


def _pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def _local_targets(page: Path) -> list[str]:
    text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)   # code blocks hold no links
    return [t for t in LINK.findall(text) if not re.match(r"[a-z]+:", t) and not t.startswith("#")]


def test_every_relative_link_and_picture_resolves():
    broken = [f"{page.relative_to(ROOT)} -> {target}" for page in _pages()
              for target in _local_targets(page)
              if not (page.parent / target.split("#")[0]).exists()]
    assert not broken, broken


def test_the_link_pattern_finds_links():
    """The check above is only as good as its pattern: the README links the docs and a picture."""
    targets = _local_targets(ROOT / "README.md")
    assert "docs/addon.md" in targets and any(t.endswith(".png") for t in targets), targets


def test_every_script_has_its_line_in_the_architecture_page():
    page = (ROOT / "docs" / "architecture.md").read_text()
    scripts = [p for folder in ("bench", "tools") for p in sorted((ROOT / folder).glob("*"))
               if p.suffix in (".py", ".sh") and not p.name.startswith("_")]
    missing = [f"{p.parent.name}/{p.name}" for p in scripts if f"`{p.name}`" not in page]
    assert not missing, f"not in docs/architecture.md: {missing}"
