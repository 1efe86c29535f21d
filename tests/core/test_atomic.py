"""The one writer rule: temporary sibling, atomic replace, the umask's mode; folders swapped whole."""

from __future__ import annotations

import os
import stat
import threading
from pathlib import Path

import pytest

from capnav.core.atomic import atomic_dir, write_text


def _mode(p: Path) -> int:
    return stat.S_IMODE(p.stat().st_mode)


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_files_and_folders_get_the_umask_mode(tmp_path: Path, umask: int) -> None:
    old = os.umask(umask)
    try:
        write_text(tmp_path / "report.md", "x")
        with atomic_dir(tmp_path / "ds") as d:
            write_text(d / "a.txt", "y")
    finally:
        os.umask(old)
    assert _mode(tmp_path / "report.md") == 0o666 & ~umask
    assert _mode(tmp_path / "ds") == 0o777 & ~umask
    assert _mode(tmp_path / "ds" / "a.txt") == 0o666 & ~umask


def test_interrupted_folder_write_keeps_the_old_folder(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    with atomic_dir(out) as d:
        write_text(d / "old.txt", "complete")
    with pytest.raises(KeyboardInterrupt), atomic_dir(out, overwrite=True) as d:
        write_text(d / "new.txt", "half")
        raise KeyboardInterrupt
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]
    assert [p.name for p in tmp_path.iterdir()] == ["ds"]  # no temporary sibling left
    with atomic_dir(out, overwrite=True) as d:
        write_text(d / "new.txt", "complete")
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"]


def test_a_folder_is_not_replaced_without_overwrite(tmp_path: Path) -> None:
    (tmp_path / "ds").mkdir()
    (tmp_path / "ds" / "mine.txt").write_text("keep")
    with pytest.raises(FileExistsError), atomic_dir(tmp_path / "ds"):
        pass
    assert (tmp_path / "ds" / "mine.txt").read_text() == "keep"


def test_two_folder_writers_one_wins_whole_the_other_is_told(tmp_path: Path) -> None:
    """Both start on an empty target; the first to finish is kept, the second fails loudly."""
    out = tmp_path / "ds"
    go = threading.Event()
    errors: list[BaseException] = []

    def writer(name: str, wait: bool) -> None:
        try:
            with atomic_dir(out) as d:
                for i in range(20):
                    write_text(d / f"{i}.txt", name)
                if wait:
                    go.wait(5)
        except BaseException as e:
            errors.append(e)
        finally:
            if not wait:
                go.set()

    slow = threading.Thread(target=writer, args=("slow", True))
    slow.start()
    writer("fast", False)
    slow.join()
    assert {p.read_text() for p in out.iterdir()} == {"fast"} and len(list(out.iterdir())) == 20
    assert len(errors) == 1 and isinstance(errors[0], FileExistsError)
    assert [p.name for p in tmp_path.iterdir()] == ["ds"]


def test_two_file_writers_leave_one_complete_file(tmp_path: Path) -> None:
    target = tmp_path / "map.txt"
    texts = [str(i) * 200_000 for i in range(4)]
    threads = [threading.Thread(target=write_text, args=(target, t)) for t in texts]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert target.read_text() in texts
    assert [p.name for p in tmp_path.iterdir()] == ["map.txt"]
