"""A hostile robot: runs the attacks named on its command line, writes what it saw to
/robocup-logs/attacks.json, then idles until it is stopped. Standard library only."""

from __future__ import annotations

import json
import os
import signal
import socket
import struct
import sys
import time

LOGS = "/robocup-logs"
seen: dict[str, object] = {}


def save() -> None:
    with open(os.path.join(LOGS, "attacks.json"), "w", encoding="utf-8") as handle:
        json.dump(seen, handle)


def rgrt(team: int, player: int, message: int) -> bytes:
    return struct.pack("<4sBBBB", b"RGrt", 2, team, player, message)


def spoof() -> None:
    """Connections to the other team's API port (once the simulator answers), then RGrt
    packets as the other team's player (GOALKEEPER, MAN_PENALISE)."""
    gc = os.environ["ROBOCUP_GAMECONTROLLER_IP"]
    answers: list[str] = []
    deadline = time.monotonic() + 60
    while len(answers) < 3 and time.monotonic() < deadline:
        try:
            with socket.create_connection((gc, 10021), timeout=5) as api:
                answers.append(api.recv(16).decode(errors="replace"))
        except OSError:
            time.sleep(0.2)  # the simulator is still starting
    seen["blue_api"] = answers
    listener = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    listener.bind(("0.0.0.0", 3838))
    listener.settimeout(60)
    try:
        listener.recvfrom(4096)  # the first RGme: the GameController's ports are open
        seen["rgme"] = True
    except OSError as exc:
        seen["rgme"] = f"failed: {exc}"
    listener.close()
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for _ in range(20):
        sock.sendto(rgrt(2, 1, 3), (gc, 3939))  # blue (team 2) player 1 GOALKEEPER
        time.sleep(0.01)
    for _ in range(5):
        sock.sendto(rgrt(2, 1, 0), (gc, 3939))  # blue player 1 MAN_PENALISE
        time.sleep(0.01)
    sock.close()


def special_files() -> None:
    """A pipe, symlinks out of the folder, a hard link, a socket, and a file that stays."""
    made = []
    for name, make in (
        ("a_fifo", lambda p: os.mkfifo(p)),
        ("shadow", lambda p: os.symlink("/etc/shadow", p)),
        ("root", lambda p: os.symlink("/", p)),
        ("environ", lambda p: os.symlink("/proc/1/environ", p)),
        ("sub/loop", lambda p: os.symlink("..", p)),
        ("dev_null", lambda p: os.mknod(p, 0o600 | 0o020000, os.makedev(1, 3))),
    ):
        path = os.path.join(LOGS, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        try:
            make(path)
            made.append(name)
        except OSError as exc:
            seen[f"{name}_error"] = str(exc)
    unix = socket.socket(socket.AF_UNIX)
    unix.bind(os.path.join(LOGS, "a_socket"))
    made.append("a_socket")
    with open(os.path.join(LOGS, "sub", "kept.txt"), "w") as handle:
        handle.write("kept\n")
    seen["special_files"] = made


def fill(path: str) -> None:
    """Write into ``path`` until the file system refuses; record how much and how it ended."""
    written = 0
    chunk = b"\0" * (1 << 20)
    try:
        with open(path, "wb") as handle:
            while written < (64 << 30):
                handle.write(chunk)
                written += len(chunk)
            handle.flush()
            os.fsync(handle.fileno())
        result = "no limit"
    except OSError as exc:
        result = f"{type(exc).__name__}: {exc.strerror}"
    seen[f"fill {path}"] = {"bytes": written, "result": result}
    try:
        os.unlink(path)
    except OSError:
        pass


def nest(depth: int) -> None:
    """``depth`` folders inside each other in /robocup-logs, a file at the bottom."""
    here = os.open(LOGS, os.O_RDONLY)
    for _ in range(depth):
        os.mkdir("d", dir_fd=here)
        deeper = os.open("d", os.O_RDONLY, dir_fd=here)
        os.close(here)
        here = deeper
    fd = os.open("bottom.txt", os.O_WRONLY | os.O_CREAT, 0o644, dir_fd=here)
    os.write(fd, b"deep\n")
    os.close(fd)
    os.close(here)
    seen["nest"] = depth


def sparse(links: int) -> None:
    """A 3 GB sparse file with a little data, and ``links`` hard links to it."""
    path = os.path.join(LOGS, "sparse.bin")
    with open(path, "wb") as handle:
        handle.write(b"head")
        handle.seek(3 * 10**9)
        handle.write(b"tail")
    for i in range(links):
        os.link(path, os.path.join(LOGS, f"link{i}"))
    seen["sparse"] = {"size": os.stat(path).st_size, "links": links}


def flood(megabytes: int) -> None:
    """``megabytes`` MB on stdout as fast as it goes."""
    line = ("x" * 1023 + "\n").encode()
    for _ in range(megabytes * 1024):
        os.write(1, line)
    seen["flood"] = megabytes


def hog(count: int) -> None:
    for _ in range(count):
        if os.fork() == 0:
            while True:
                pass


def main(argv: list[str]) -> None:
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    for arg in argv:
        try:
            if arg == "spoof":
                spoof()
            elif arg == "special-files":
                special_files()
            elif arg.startswith("fill="):
                fill(arg.partition("=")[2])
            elif arg.startswith("exit="):
                sys.exit(int(arg.partition("=")[2]))
            elif arg.startswith("hog="):
                hog(int(arg.partition("=")[2]))
            elif arg.startswith("nest="):
                nest(int(arg.partition("=")[2]))
            elif arg.startswith("sparse="):
                sparse(int(arg.partition("=")[2]))
            elif arg.startswith("flood="):
                flood(int(arg.partition("=")[2]))
        except Exception as exc:  # an attack that breaks is reported, the next one still runs
            seen[f"{arg} crashed"] = repr(exc)
        save()
    print("attacks done", json.dumps(seen), flush=True)
    while True:
        time.sleep(1)


if __name__ == "__main__":
    main(sys.argv[1:])
