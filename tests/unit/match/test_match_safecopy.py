"""Collecting a team's log folder: regular files and directories only, nothing followed."""

from __future__ import annotations

import os
import socket
import stat
from pathlib import Path

from orchestrator.match.logfs import LogFolder, collect
from orchestrator.match.safecopy import copy_tree, sweep


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
