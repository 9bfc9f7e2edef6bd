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


def killed_mid_write(folder: Path, relative: str) -> None:
    """A process that holds the folder's lock and dies (``os._exit``) while
    :func:`atomic_write` writes ``relative``: its temporary stays on disk."""
    code = ("import os, sys\nfrom pathlib import Path\n"
            "from gnngarment.io.atomic import FolderLock, atomic_write\n"
            "with FolderLock(sys.argv[1]):\n"
            "    atomic_write(Path(sys.argv[1]) / sys.argv[2],"
            " lambda stream: (stream.write(b'half'), stream.flush(), os._exit(9)))\n")
    assert subprocess.run([sys.executable, "-c", code, str(folder), relative]).returncode == 9


def test_only_the_temporaries_a_killed_run_made_are_removed(tmp_path: Path) -> None:
    """A killed run's ``.<name>.<8 hex>.tmp`` goes; a user's hidden ``.draft.tmp`` (issue
    15: `prepare` deleted it), a file the user named like ours (issue 38: `animate`
    deleted it) and files outside the run's folders stay."""
    (tmp_path / "sequences" / "sub").mkdir(parents=True)
    killed_mid_write(tmp_path, "sequences/sub/a.npz")
    ours = list((tmp_path / "sequences" / "sub").glob(".a.npz.*.tmp"))
    assert len(ours) == 1
    draft = tmp_path / "sequences" / "sub" / ".draft.tmp"
    draft.write_bytes(b"mine")
    lookalike = tmp_path / "sequences" / ".b.npz.0123abcd.tmp"
    lookalike.write_bytes(b"mine too")
    elsewhere = tmp_path / "notes" / ".b.npz.0123abcd.tmp"
    elsewhere.parent.mkdir()
    elsewhere.write_bytes(b"x")
    atomic_write_bytes(tmp_path / "sequences" / "kept.npz", b"data")
    with FolderLock(tmp_path) as lock:
        assert lock.remove_stale_temporaries(("sequences", ".")) == 1
    assert not ours[0].exists() and draft.read_bytes() == b"mine"
    assert lookalike.read_bytes() == b"mine too" and elsewhere.exists()
    assert (tmp_path / "sequences" / "kept.npz").read_bytes() == b"data"
    with pytest.raises(RuntimeError):
        FolderLock(tmp_path).remove_stale_temporaries(("sequences",))


def test_a_recorded_temporary_replaced_by_a_symlink_is_not_followed(tmp_path: Path) -> None:
    """After a kill, the recorded name now a symlink to a user's file: the link is not
    followed (the user's file stays)."""
    out, user = tmp_path / "out", tmp_path / "user"
    out.mkdir()
    user.mkdir()
    killed_mid_write(out, "g.glb")
    (temp,) = out.glob(".g.glb.*.tmp")
    temp.unlink()
    (user / "precious.glb").write_bytes(b"user")
    temp.symlink_to(user / "precious.glb")
    with FolderLock(out) as lock:
        assert lock.remove_stale_temporaries((".",)) == 0
    assert (user / "precious.glb").read_bytes() == b"user"
