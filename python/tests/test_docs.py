"""The Python code blocks of README.md and docs/*.md, each run as written.

Every ```python block of those pages is one test. It runs in a fresh namespace, with a
fresh temporary folder as working directory; that folder links `corpora/`, `benches/`,
`python/`, `scripts/` and `.cache/` of the repository, so the relative paths the blocks
use (`corpora/scenes/demo/arm.xml`, `benches/scenes/lift5.toml`...) work, and whatever a
block writes stays out of the repository. The repository root is also in the environment
variable MJCF_FORGE_ROOT while a block runs.

Run: .cache/venv/bin/python -m pytest python/tests/test_docs.py -q -p no:cacheprovider
(after scripts/setup.sh, which installs the package and the `mujoco` it compiles with).
The other blocks are tested by tests/docs.rs (```sh and ```toml) and as doctests
(```rust, through src/lib.rs); docs/contributing.md describes the conventions.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# What the blocks may read, linked into their working folder.
LINKED = ("corpora", "benches", "python", "scripts", ".cache")

FENCE = re.compile(r"^( {0,3}|\s*)(`{3,})\s*([^`\s]*)[^`]*$")


def blocks(page: Path) -> list[tuple[str, int, str]]:
    """(language, first line number, code) of each fenced block of a Markdown page."""
    found = []
    lines = page.read_text().split("\n")
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, ticks, lang = len(m.group(1)), m.group(2), m.group(3)
        start = i + 1
        body = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(ticks):
            line = lines[i]
            # Blocks inside list items are indented; take the fence's indentation off.
            body.append(line[indent:] if line[:indent].strip() == "" else line)
            i += 1
        found.append((lang, start + 1, "\n".join(body) + "\n"))
        i += 1
    return found


PYTHON_BLOCKS = [
    pytest.param(code, id=f"{page.relative_to(ROOT)}:{line}")
    for page in PAGES
    for lang, line, code in blocks(page)
    if lang == "python"
]


def test_the_pages_have_python_blocks():
    assert len(PYTHON_BLOCKS) >= 5, [p.id for p in PYTHON_BLOCKS]


@pytest.mark.parametrize("code", PYTHON_BLOCKS)
def test_python_block_runs(code: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    for name in LINKED:
        if (ROOT / name).exists():
            (tmp_path / name).symlink_to(ROOT / name)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MJCF_FORGE_ROOT", str(ROOT))
    namespace = {"__name__": "__docs__"}
    exec(compile(code, "<docs block>", "exec"), namespace)
