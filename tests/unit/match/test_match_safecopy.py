"""Collecting a team's log folder: regular files and directories only, nothing followed."""

from __future__ import annotations

import os
import socket
import stat
from pathlib import Path

from orchestrator.match.logfs import LogFolder, collect
from orchestrator.match.safecopy import copy_tree, remove_tree, restrict, sweep


def _hostile_folder(root: Path, outside: Path) -> None:
    (root / "sub").mkdir(parents=True)
    (root / "sub" / "kept.txt").write_text("kept\n")
    (root / "top.log").write_bytes(b"x" * 3000)
    os.mkfifo(root / "a_fifo")
    (root / "secret").symlink_to(outside)
    (root / "rootdir").symlink_to("/")
    (root / "sub" / "loop").symlink_to("..")
    unix = socket.socket(socket.AF_UNIX)
    unix.bind(str(root / "a_socket"))
    unix.close()


def test_copy_takes_files_and_directories_and_lists_the_rest(tmp_path: Path) -> None:
    outside = tmp_path / "outside.txt"
    outside.write_text("not the team's\n")
    source, target = tmp_path / "logs", tmp_path / "out" / "robocup-logs"
    _hostile_folder(source, outside)
    report = copy_tree(source, target)
    assert (target / "sub" / "kept.txt").read_text() == "kept\n"
    assert (target / "top.log").stat().st_size == 3000
    assert (report.files, report.bytes) == (2, 3005)
    assert {(s["path"], s["kind"]) for s in report.skipped} == {
        ("a_fifo", "pipe"), ("secret", "symlink"), ("rootdir", "symlink"),
        ("sub/loop", "symlink"), ("a_socket", "socket"),
    }
    found = {p.relative_to(target).as_posix() for p in target.rglob("*")}
    assert found == {"sub", "sub/kept.txt", "top.log"}
    assert stat.S_IMODE(target.stat().st_mode) == 0o700
    assert stat.S_IMODE((target / "sub").stat().st_mode) == 0o700
    assert stat.S_IMODE((target / "top.log").stat().st_mode) == 0o600


def test_sweep_removes_special_entries_in_place(tmp_path: Path) -> None:
    outside = tmp_path / "outside.txt"
    outside.write_text("not the team's\n")
    folder = tmp_path / "robocup-logs"
    _hostile_folder(folder, outside)
    report = sweep(folder)
    assert report.skipped_count == 5 and report.files == 2
    assert {p.relative_to(folder).as_posix() for p in folder.rglob("*")} == {
        "sub", "sub/kept.txt", "top.log"}
    assert outside.read_text() == "not the team's\n"


def test_collect_of_an_unreadable_folder_reports_instead_of_raising(tmp_path: Path) -> None:
    folder = LogFolder(path=tmp_path / "gone", cap_bytes=None)
    report = collect(folder, tmp_path / "dest")
    assert report.skipped_count == 1 and "unreadable" in report.skipped[0]["kind"]


def _nest(root: Path, depth: int) -> Path:
    """``depth`` folders inside each other (walked with a relative path: no PATH_MAX)."""
    root.mkdir(parents=True)
    here = os.open(root, os.O_RDONLY)
    try:
        for _ in range(depth):
            os.mkdir("d", dir_fd=here)
            deeper = os.open("d", os.O_RDONLY, dir_fd=here)
            os.close(here)
            here = deeper
        fd = os.open("bottom.txt", os.O_WRONLY | os.O_CREAT, 0o644, dir_fd=here)
        os.write(fd, b"deep\n")
        os.close(fd)
    finally:
        os.close(here)
    return root


def test_1500_nested_folders_are_walked_without_recursion_and_cut_at_the_depth_limit(
    tmp_path: Path,
) -> None:
    source = _nest(tmp_path / "logs", 1500)
    (source / "top.txt").write_text("top\n")
    target = tmp_path / "out"
    report = copy_tree(source, target, max_depth=100)
    assert (target / "top.txt").read_text() == "top\n"
    assert report.skipped_count == 1
    assert report.skipped[0]["kind"] == "directory nested deeper than 100 folders"
    assert report.skipped[0]["path"].count("/") == 100
    restrict(target)  # the same walk: no RecursionError
    removed = tmp_path / "swept"
    _nest(removed, 300)
    swept = sweep(removed, max_depth=50)
    assert swept.skipped_count == 1 and swept.files == 0
    assert len(list(removed.rglob("*"))) == 50  # the folders deeper than 50 are gone
    remove_tree(source)  # in time linear in the depth (each folder moved up first)
    assert not source.exists()


def test_a_sparse_file_and_its_hard_links_cost_their_data_once(tmp_path: Path) -> None:
    source, target = tmp_path / "logs", tmp_path / "out"
    source.mkdir()
    with (source / "sparse.bin").open("wb") as handle:
        handle.write(b"head")
        handle.seek(3 * 10**9)  # 3 GB, nearly all hole
        handle.write(b"tail")
    for i in range(5):
        os.link(source / "sparse.bin", source / f"link{i}")
    report = copy_tree(source, target, limit_bytes=10**9)
    assert report.stopped is None
    assert report.files == 6 and report.links == 5
    assert report.bytes < 1 << 22  # the data blocks, not 6 x 3 GB
    copy = target / "sparse.bin"
    assert copy.stat().st_size == 3 * 10**9 + 4
    assert copy.stat().st_blocks * 512 < 1 << 22
    assert (target / "link4").stat().st_ino == copy.stat().st_ino
    with copy.open("rb") as handle:
        assert handle.read(4) == b"head"
        handle.seek(3 * 10**9)
        assert handle.read() == b"tail"


def test_the_copy_stops_at_its_limit_and_says_where(tmp_path: Path) -> None:
    source, target = tmp_path / "logs", tmp_path / "out"
    source.mkdir()
    for name in ("a.log", "b.log", "c.log"):
        (source / name).write_bytes(os.urandom(400_000))
    report = copy_tree(source, target, limit_bytes=1_000_000)
    assert report.bytes == 1_000_000
    assert report.stopped is not None and "b.log" not in report.stopped
    assert "limit of 1000000 bytes in c.log" in report.stopped
    assert (target / "c.log").stat().st_size == 200_000
    assert report.record().stopped == report.stopped
