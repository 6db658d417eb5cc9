"""Two processes storing the same NLP cache entry at once (the cache tests' race)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def race_two_writers(script: str, root: Path, timeout_s: float) -> None:
    """Run ``script`` (which stores the entry "race" under ``sys.argv[1]``) twice at once.

    Both must succeed and leave exactly the one entry, no temporary directory.
    """
    writers = [
        subprocess.Popen([sys.executable, "-c", script, str(root)], stderr=subprocess.PIPE)
        for _ in range(2)
    ]
    for writer in writers:
        _, err = writer.communicate(timeout=timeout_s)
        assert writer.returncode == 0, err.decode()
    assert [p.name for p in root.iterdir()] == ["race"]  # no temporary directory left
