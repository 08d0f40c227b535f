"""The marker of a finished sweep item: ``sweep_item.json``, written last into the item's folder,
records the item's fingerprint and the SHA-256 of its ``summary.json``; a summary is trusted only
if it is the one its marker vouches for (:func:`verified_summary`)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

__all__ = ["MARKER", "digest", "read_marker", "verified_summary"]

#: The marker's file name in an item's folder.
MARKER = "sweep_item.json"


def read_marker(folder: Path) -> dict[str, Any] | None:
    """The marker document of an item's folder (None if absent or unreadable)."""
    try:
        doc = json.loads((folder / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None


def digest(path: Path) -> str | None:
    """SHA-256 of a file (None if it cannot be read)."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def verified_summary(folder: Path) -> dict[str, Any] | None:
    """The item's ``summary.json`` document, or None unless it is the one its marker vouches
    for: the marker (written last) records the SHA-256 of the summary, and the file read now
    must have it and parse (a summary truncated or edited after the item finished is not
    trusted)."""
    m = read_marker(folder)
    if m is None or not m.get("summary_sha256"):
        return None
    path = folder / "summary.json"
    try:
        data = path.read_bytes()
    except OSError:
        return None
    if hashlib.sha256(data).hexdigest() != m["summary_sha256"]:
        return None
    try:
        doc = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None
