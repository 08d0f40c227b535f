"""Checks shared by the command-line tests (a helper module, not collected by pytest)."""

from __future__ import annotations


def one_line(err: str) -> str:
    """The only non-blank line of ``err`` (fails if there are several)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    return lines[0]


def assert_refused(code: int, err: str, words) -> str:
    """Bad input: exit code 2 and one ``fegear: error: ...`` line naming every word."""
    assert code == 2, err
    line = one_line(err)
    assert line.startswith("fegear: error: "), line
    for w in words:
        assert w in line, f"{w!r} not in {line!r}"
    return line


def summary_value(doc, dotted: str):
    """The entry ``a.b.0.c`` of a ``summary.json`` document (digits index lists); fails naming
    the key when it is missing."""
    for k in dotted.split("."):
        if k.isdigit():
            doc = doc[int(k)]
        else:
            assert k in doc, f"summary.json has no {dotted!r}"
            doc = doc[k]
    return doc
