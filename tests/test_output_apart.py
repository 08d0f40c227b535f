"""Work done in a second process (:mod:`fegear.output.apart`): the pictures of a run drawn
while its VTK files are written. What the caller gets does not depend on where it was done."""

from __future__ import annotations

import os

import pytest

from fegear.output.apart import apart


def test_work_apart_returns_what_it_returns_here(tmp_path):
    """The child writes its file and hands back its return value; the parent sees both."""
    target = tmp_path / "made_apart.txt"

    def work():
        target.write_text(str(os.getpid()))
        return [target, 42]

    wait = apart(work, fork=True)
    assert wait() == [target, 42]
    assert int(target.read_text()) != os.getpid()  # written by another process


def test_failed_work_is_done_again_here_and_raises_here(tmp_path):
    """A child that fails is reported and the work runs again in the caller, whose error the
    caller sees (not a lost child's)."""
    calls = tmp_path / "calls"
    calls.mkdir()

    def work():
        (calls / str(os.getpid())).touch()
        raise ValueError("no picture")

    wait = apart(work, fork=True)
    with pytest.raises(ValueError, match="no picture"):
        wait()
    pids = {int(p.name) for p in calls.iterdir()}
    assert os.getpid() in pids and len(pids) == 2  # once apart, once here


def test_without_fork_the_work_runs_here_when_asked():
    """``fork=False`` (one process wanted): nothing runs until the result is asked for, here."""
    ran = []
    wait = apart(lambda: ran.append(os.getpid()) or "here", fork=False)
    assert ran == []
    assert wait() == "here" and ran == [os.getpid()]
