"""Atomic writes and output-folder locks (gnngarment/io/atomic.py)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from gnngarment.io.atomic import FolderBusyError, FolderLock, atomic_write_bytes


def test_a_held_folder_refuses_a_second_run_even_from_another_process(tmp_path: Path) -> None:
    with FolderLock(tmp_path, "build"):
        with pytest.raises(FolderBusyError, match=r"another build \(pid \d+\)"):
            FolderLock(tmp_path, "build").__enter__()
        code = ("import sys; from gnngarment.io.atomic import FolderLock, FolderBusyError\n"
                "try:\n    FolderLock(sys.argv[1]).__enter__()\n"
                "except FolderBusyError:\n    sys.exit(3)\n")
        assert subprocess.run([sys.executable, "-c", code, str(tmp_path)]).returncode == 3
    with FolderLock(tmp_path, "build"):  # released on exit
        pass


def test_only_our_stale_temporaries_are_removed(tmp_path: Path) -> None:
    """A killed run's ``.<name>.<8 hex>.tmp`` goes; a user's hidden ``.draft.tmp`` (issue
    15: `prepare` deleted it) and files outside the run's folders stay."""
    (tmp_path / "sequences" / "sub").mkdir(parents=True)
    ours = tmp_path / "sequences" / "sub" / ".a.npz.0123abcd.tmp"
    ours.write_bytes(b"x")
    draft = tmp_path / "sequences" / "sub" / ".draft.tmp"
    draft.write_bytes(b"mine")
    elsewhere = tmp_path / "notes" / ".b.npz.0123abcd.tmp"
    elsewhere.parent.mkdir()
    elsewhere.write_bytes(b"x")
    atomic_write_bytes(tmp_path / "sequences" / "kept.npz", b"data")
    with FolderLock(tmp_path) as lock:
        assert lock.remove_stale_temporaries(("sequences", ".")) == 1
    assert not ours.exists() and draft.read_bytes() == b"mine" and elsewhere.exists()
    assert (tmp_path / "sequences" / "kept.npz").read_bytes() == b"data"
    with pytest.raises(RuntimeError):
        FolderLock(tmp_path).remove_stale_temporaries(("sequences",))
