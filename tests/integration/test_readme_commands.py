"""Every command of the READMEs, run as written from a fresh copy of the repository.

The commands are read from the ``sh`` (``shell``, ``bash``) and ``python`` code blocks of
README.md, configs/README.md, images/README.md and docs/tournament.md (the tournament operator's
guide), in order, and run with the working directory
at the root of a copy of the repository (tracked and new files, no build output), the project's
virtual environment linked in as ``.venv`` and on PATH (as after ``. .venv/bin/activate``) and no
``MUJOCO_GL`` (the program must choose). ``make X`` runs the recipe of ``X`` from the Makefile
(``make scrimmage``: the scrimmage itself, the set-up being what this suite runs in).

Each command has its expected outcome in ``OUTCOMES`` (exit code and the files it makes); a
command the table does not know fails the test, so a new README command comes with its check.
A command marked ``# not run in CI: <reason>`` in the README is skipped with that reason.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
READMES = ("README.md", "configs/README.md", "images/README.md", "docs/tournament.md")
SHELL_FENCES = {"sh", "shell", "bash"}
MARKER = re.compile(r"#\s*not run in CI:\s*(?P<reason>.*\S)\s*$")
FENCE = re.compile(r"^```\s*(?P<info>[\w-]*)\s*$")

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]


@dataclass(frozen=True)
class Command:
    readme: str
    line: int
    text: str  # as written (continuation lines joined, comments kept)
    language: str  # "sh" or "python"
    skip: str | None  # the reason given by a "# not run in CI:" marker

    @property
    def key(self) -> str:
        """The command without comments, single spaces, shell quoting normalised (``'...'``):
        what OUTCOMES is keyed by."""
        if self.language == "python":
            return self.text.strip()
        return shlex.join(shlex.split(self.text.replace("\\\n", " "), comments=True))

    @property
    def id(self) -> str:
        return f"{self.readme}:{self.line}"


def readme_commands(root: Path = REPO) -> list[Command]:
    """The commands of the READMEs' ``sh`` and ``python`` blocks, in document order."""
    found: list[Command] = []
    for name in READMES:
        language: str | None = None
        pending: list[str] = []
        start = 0
        block_start = 0
        in_block = False
        for number, line in enumerate((root / name).read_text().splitlines(), start=1):
            fence = FENCE.match(line.strip())
            if fence and not in_block:
                in_block = True
                info = fence["info"]
                language = "sh" if info in SHELL_FENCES else "python" if info == "python" else None
                pending, block_start = [], number + 1
                continue
            if fence and in_block:
                in_block = False
                if language == "python" and pending:
                    found.append(Command(name, block_start, "\n".join(pending), "python", None))
                pending = []
                continue
            if not in_block or language is None:
                continue
            if language == "python":
                pending.append(line)
                continue
            if not pending and (not line.strip() or line.lstrip().startswith("#")):
                continue
            if not pending:
                start = number
            pending.append(line.rstrip())
            if line.rstrip().endswith("\\"):
                continue
            text = "\n".join(pending)
            marker = MARKER.search(pending[-1])
            found.append(Command(name, start, text, "sh", marker["reason"] if marker else None))
            pending = []
    return found


def make_recipe(root: Path, target: str) -> str:
    """The shell lines of a Makefile target, with its ``$(VARIABLES)`` expanded."""
    variables: dict[str, str] = {}
    recipe: list[str] = []
    lines = (root / "Makefile").read_text().splitlines()
    for line in lines:
        assignment = re.match(r"^([A-Z_]+)\s*(?::=|\?=|=)\s*(.*)$", line)
        if assignment:
            variables.setdefault(assignment[1], assignment[2].strip())
    for index, line in enumerate(lines):
        if re.match(rf"^{re.escape(target)}\s*:", line):
            for body in lines[index + 1:]:
                if not body.startswith("\t"):
                    break
                recipe.append(body.strip())
            break
    assert recipe, f"Makefile has no recipe for {target!r}"
    text = " && ".join(recipe)
    for _ in range(5):
        text = re.sub(r"\$\(([A-Z_]+)\)", lambda m: variables.get(m[1], ""), text)
    return text


@dataclass
class Ran:
    command: Command
    returncode: int
    stdout: str
    stderr: str

    def describe(self) -> str:
        return (f"{self.command.id}: {self.command.text!r} exited {self.returncode}\n"
                f"--- stdout\n{self.stdout[-3000:]}\n--- stderr\n{self.stderr[-3000:]}")


Check = Callable[[Ran, Path], None]


@dataclass(frozen=True)
class Outcome:
    check: Check
    timeout_s: float = 300.0
    after: tuple[str, ...] = ()  # keys of commands that must have run first
    server: bool = False  # runs until stopped: wait for its URL, fetch it, then Ctrl-C


# ---- checks ----------------------------------------------------------------------------------

def exit_zero(ran: Ran, root: Path) -> None:
    assert ran.returncode == 0, ran.describe()
    assert "Traceback" not in ran.stderr, ran.describe()


def check_ok(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    assert ": ok (" in ran.stdout, ran.describe()


def official_model_ok(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    report = json.loads(ran.stdout)
    assert report["valid"] is True, ran.describe()
    servos = report["files"][0]["measurements"]["servos"]
    assert servos and all("@" in s for s in servos.values()), servos  # catalogue servos only


def scrimmage_played(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    out = root / "matches" / "scrimmage"
    assert json.loads((out / "report.json").read_text())["status"] == "success"
    results = json.loads((out / "results.json").read_text())
    assert results["status"] == "success" and results["final_state"] == "FINISHED", results
    play = results["play"]  # the default scrimmage is football: both halves played, a kick
    assert play["both_halves_playing"], play
    assert sum(play["kicks"].values()) >= 1, play
    assert (out / "public" / "replay.hlvsrec").is_file()
    assert "hlvs render matches/scrimmage/public/replay.hlvsrec -o match.mp4" in ran.stdout
    assert "hlvs view matches/scrimmage" in ran.stdout


def video_made(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    results = json.loads((root / "matches" / "scrimmage" / "results.json").read_text())
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-show_entries", "stream=codec_type,codec_name:format=duration",
         "-of", "json", str(root / "match.mp4")],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    info = json.loads(probe.stdout)
    assert info["streams"][0]["codec_type"] == "video"
    assert info["streams"][0]["codec_name"] == "h264"
    assert float(info["format"]["duration"]) == pytest.approx(
        results["sim_time_ms"] / 1000.0, abs=2.0
    )


def viewer_serves(ran: Ran, root: Path) -> None:
    urls = re.findall(r"http://127\.0\.0\.1:\d+/\S+", ran.stdout)
    assert urls, ran.describe()
    with urllib.request.urlopen(urls[0], timeout=30) as response:  # noqa: S310 (loopback)
        assert response.status == 200
        assert b"<html" in response.read().lower()


def bench_json(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    document = json.loads(ran.stdout.strip().splitlines()[-1])
    assert document["bench"] == "envs", document
    assert document["vector_inprocess"]["ratio"] > 0, document


def camera_frames_written(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    frames = sorted((root / "frames").glob("red-1_*.png"))
    assert frames, ran.describe()
    assert frames[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def mcap_written(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    assert (root / "match.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"


def learnt_kick(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    document = json.loads(ran.stdout.strip().splitlines()[0])
    assert document["example"] == "learn_kick" and document["episodes"] > 0, document


def team_added(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    assert json.loads(ran.stdout)["team"] == "Red Robots"
    assert (root / "service-data").is_dir()


def token_printed(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    assert re.fullmatch(r"hlvs_[0-9a-f]+_\S+", ran.stdout.strip()), ran.describe()


def compose_written(ran: Ran, root: Path) -> None:
    exit_zero(ran, root)
    written = root / "match" / "docker-compose.yml"
    assert written.is_file()
    compose = shutil.which("docker-compose")
    if compose is not None:
        subprocess.run([compose, "-f", str(written), "config", "-q"], check=True, cwd=root)


SCRIMMAGE = "make scrimmage"
ADMIN_FIRST = "hlvs admin team add 'Red Robots' --email red@example.org --data-dir service-data"
OUTCOMES: dict[str, Outcome] = {
    # README.md
    SCRIMMAGE: Outcome(scrimmage_played, timeout_s=900),
    ". .venv/bin/activate": Outcome(exit_zero),
    "hlvs render matches/scrimmage/public/replay.hlvsrec -o match.mp4": Outcome(
        video_made, timeout_s=1500, after=(SCRIMMAGE,)
    ),
    "hlvs render matches/scrimmage/public/replay.hlvsrec --camera red-1 -o frames --fps 0.2": (
        Outcome(camera_frames_written, timeout_s=600, after=(SCRIMMAGE,))
    ),
    "hlvs view matches/scrimmage": Outcome(viewer_serves, timeout_s=60, after=(SCRIMMAGE,),
                                           server=True),
    ".venv/bin/python examples/learn_kick.py --seed 1 --iterations 1 --population 3": Outcome(
        learnt_kick
    ),
    "hlvs export matches/scrimmage/public/replay.hlvsrec -o match.mcap": Outcome(
        mcap_written, after=(SCRIMMAGE,)
    ),
    "hlvs bench envs --rounds 2 --block 200 --json": Outcome(bench_json),
    ADMIN_FIRST: Outcome(team_added),
    "hlvs admin token issue --team 'Red Robots' --days 90": Outcome(
        token_printed, after=(ADMIN_FIRST,)
    ),
    "hlvs admin token issue --operator": Outcome(token_printed, after=(ADMIN_FIRST,)),
    # configs/README.md
    "hlvs check configs/examples/kid_4v4_official/team_red.json": Outcome(check_ok),
    "hlvs check --class KID configs/examples/kid_4v4_official/team_red.json": Outcome(check_ok),
    "hlvs check configs/examples/kid_4v4_official/game.json": Outcome(check_ok),
    "hlvs check --require-images configs/examples/kid_4v4_official/game.json": Outcome(check_ok),
    "hlvs check configs/examples/credentials/sftp_key.json": Outcome(check_ok),
    "hlvs check configs/examples/robots/wolfgang": Outcome(check_ok),
    "hlvs check --official --json configs/examples/robots/wolfgang": Outcome(official_model_ok),
    "hlvs check configs/examples/schedule/knockout.yaml": Outcome(check_ok),
    "hlvs schedule list configs/examples/schedule/knockout.yaml": Outcome(exit_zero),
    # docs/tournament.md (the operator's guide; make scrimmage, the activation, the operator
    # token and the credentials check are README.md's and configs/README.md's commands)
    "chmod 600 'configs/examples/credentials/*.json' configs/examples/credentials/id_ed25519": (
        Outcome(exit_zero)),
    "hlvs check configs/examples/schedule/tournament.yaml": Outcome(check_ok),
    "hlvs schedule list configs/examples/schedule/tournament.yaml": Outcome(exit_zero),
    "hlvs logs status --store matches/example-cup/log-store": Outcome(exit_zero),
    # images/README.md
    "hlvs compose configs/examples/scrimmage_1v1/game.json -o match/docker-compose.yml": Outcome(
        compose_written
    ),
}


def outcome_of(command: Command) -> Outcome:
    """The expected outcome; a python block is expected to run without error."""
    if command.language == "python":
        return OUTCOMES.get(command.key, Outcome(exit_zero))
    return OUTCOMES[command.key]


# ---- running ---------------------------------------------------------------------------------

def _fresh_copy(destination: Path) -> Path:
    """The repository's tracked and new files (nothing ignored: no build output, no matches)."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=REPO, capture_output=True, check=True,
    ).stdout.decode().split("\0")  # fmt: skip
    for name in filter(None, listed):
        source = REPO / name
        if source.is_file():
            target = destination / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
    (destination / ".venv").symlink_to(Path(sys.prefix))
    return destination


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    for name in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "VIRTUAL_ENV", "PYTHONPATH"):
        env.pop(name, None)
    env["PATH"] = f"{Path(sys.prefix) / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    return env


class Session:
    """One fresh copy; commands run at most once each, in the order they are asked for."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.ran: dict[str, Ran] = {}
        self.by_key = {c.key: c for c in readme_commands(root) if c.skip is None}

    def run(self, command: Command) -> Ran:
        if command.key in self.ran:
            return self.ran[command.key]
        outcome = outcome_of(command)
        for key in outcome.after:
            self.run(self.by_key[key])
        argv = self._argv(command)
        if outcome.server:
            ran = self._serve(command, argv, outcome)
        else:
            done = subprocess.run(
                argv, cwd=self.root, env=_environment(), capture_output=True, text=True,
                timeout=outcome.timeout_s, check=False,
            )  # fmt: skip
            ran = Ran(command, done.returncode, done.stdout, done.stderr)
        self.ran[command.key] = ran
        return ran

    def _argv(self, command: Command) -> list[str]:
        if command.language == "python":
            return [sys.executable, "-c", command.text]
        make = re.fullmatch(r"make (\S+)", command.key)
        text = make_recipe(self.root, make[1]) if make else command.text
        return ["bash", "-e", "-c", text]

    def _serve(self, command: Command, argv: list[str], outcome: Outcome) -> Ran:
        process = subprocess.Popen(
            argv, cwd=self.root, env=_environment(), stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, start_new_session=True,
        )  # fmt: skip
        assert process.stdout is not None
        lines: list[str] = []
        watchdog = threading.Timer(outcome.timeout_s, os.killpg, (process.pid, signal.SIGKILL))
        watchdog.start()
        try:
            for line in iter(process.stdout.readline, ""):  # bounded by the check's timeout
                lines.append(line)
                if re.search(r"http://127\.0\.0\.1:\d+/", line):
                    ran = Ran(command, 0, "".join(lines), "")
                    outcome.check(ran, self.root)
                    break
        finally:
            watchdog.cancel()
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
            try:
                rest, err = process.communicate(timeout=outcome.timeout_s)
            except subprocess.TimeoutExpired:
                process.kill()
                rest, err = process.communicate()
        return Ran(command, process.returncode, "".join(lines) + rest, err)

    def cleanup(self) -> None:
        game = self.root / "matches" / "scrimmage" / "config" / "game.json"
        if game.is_file():
            match_id = json.loads(game.read_text())["match_id"]
            subprocess.run(
                [str(Path(sys.prefix) / "bin" / "hlvs"), "cleanup", "--match", match_id],
                capture_output=True, timeout=120, check=False,
            )  # fmt: skip


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Session]:
    root = _fresh_copy(tmp_path_factory.mktemp("fresh") / "hlvs-runner")
    session = Session(root)
    try:
        yield session
    finally:
        session.cleanup()


COMMANDS = readme_commands()


def test_the_readmes_have_commands_and_each_is_known_or_marked() -> None:
    assert {c.readme for c in COMMANDS} == set(READMES)
    unknown = [
        f"{c.id}: {c.key}" for c in COMMANDS
        if c.skip is None and c.language == "sh" and c.key not in OUTCOMES
    ]  # fmt: skip
    assert not unknown, "README commands without an expected outcome in OUTCOMES:\n" + "\n".join(
        unknown
    )
    keys = {c.key for c in COMMANDS}
    assert not set(OUTCOMES) - keys, "OUTCOMES for commands no README has any more"


# Each command is bounded by its own outcome's timeout (and those of the commands it runs after),
# not by the suite's 600 s per test: the README's render runs longer while another test runs.
LONGEST_S = max(
    o.timeout_s + sum(OUTCOMES[k].timeout_s for k in o.after) for o in OUTCOMES.values()
)


@pytest.mark.timeout(LONGEST_S + 60)
@pytest.mark.parametrize("command", COMMANDS, ids=[c.id for c in COMMANDS])
def test_readme_command(command: Command, session: Session) -> None:
    if command.skip is not None:
        pytest.skip(f"marked in {command.readme}: not run in CI: {command.skip}")
    if command.language == "sh" and command.key not in OUTCOMES:
        pytest.fail(f"{command.id}: no expected outcome for {command.key!r}")
    outcome = outcome_of(command)
    ran = session.run(command)
    if not outcome.server:
        outcome.check(ran, session.root)


def test_commands_are_read_as_written(tmp_path: Path) -> None:
    """Continuation lines, comments, markers and python blocks, on a README of our own."""
    for name in READMES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("no blocks\n")
    (tmp_path / "README.md").write_text(
        "text\n```sh\n# a comment line\nhlvs check a.json   # checks a\n\n"
        "hlvs registry enforce --url U \\\n    --json  # not run in CI: needs a registry\n```\n"
        "```\nnot a command\n```\n```python\nimport json\nprint(1)\n```\n"
    )
    found = readme_commands(tmp_path)
    assert [(c.line, c.key, c.skip, c.language) for c in found] == [
        (4, "hlvs check a.json", None, "sh"),
        (6, "hlvs registry enforce --url U --json", "needs a registry", "sh"),
        (13, "import json\nprint(1)", None, "python"),
    ]
    (tmp_path / "Makefile").write_text(
        "VENV := .venv\nHLVS := $(VENV)/bin/hlvs\n\nscrimmage: setup\n"
        "\t$(HLVS) scrimmage --out matches/scrimmage\n\ntest: setup\n\tpytest\n"
    )
    assert make_recipe(tmp_path, "scrimmage") == ".venv/bin/hlvs scrimmage --out matches/scrimmage"
