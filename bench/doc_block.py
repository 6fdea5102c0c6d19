"""Rewriting the measured part of a docs page between two marker lines (the benchmarks'
``--out`` / docs updates): :func:`replace_block`."""

from __future__ import annotations

import re
from pathlib import Path


def replace_block(path: Path, text: str, begin: str, end: str) -> None:
    """Replace what lies between the markers ``begin`` and ``end`` in ``path`` with ``text``
    (markers kept); exits with a message naming the file if either marker is missing."""
    doc = path.read_text()
    if begin not in doc or end not in doc:
        raise SystemExit(f"{path} has no {begin} ... {end} block")
    block = f"{begin}\n{text}\n{end}"
    path.write_text(re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: block, doc,
                           count=1, flags=re.S))
