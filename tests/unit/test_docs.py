"""The docs name modules that exist (avoids a stale architecture page)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_every_module_named_in_step_md_exists():
    text = (ROOT / "docs" / "step.md").read_text()
    paths = set(re.findall(r"`(src/tumble/[\w/]+\.py)`", text))
    assert len(paths) >= 6
    missing = sorted(p for p in paths if not (ROOT / p).is_file())
    assert not missing, f"docs/step.md names modules that do not exist: {missing}"


def test_readme_quick_start_is_the_two_commands():
    text = (ROOT / "README.md").read_text()
    assert "make demo" in text and "make test" in text
    assert "make test" in (ROOT / ".ci" / "run").read_text()
