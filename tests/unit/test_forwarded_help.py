"""``hlvs <forwarded command> --help`` (benchmarks, render) parses before the heavy imports:
the target parsers import MuJoCo, numpy, gymnasium, Docker... only after their arguments."""

from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

from hlvs.cli import build_parser, walk

# What a forwarded command may import only once its arguments are parsed.
HEAVY_AFTER_PARSE = (
    "mujoco", "numpy", "gymnasium", "docker", "zenoh", "boto3", "asyncssh", "paramiko",
    "sqlalchemy", "fastapi", "playwright", "orchestrator.match", "orchestrator.engine",
    "orchestrator.delivery", "simulator.world", "simulator.api", "simulator.replay", "referee",
    "envs",
)  # fmt: skip

# The child runs `hlvs <command> --help`; a command that executes `python -m MODULE` runs that
# module in the same interpreter instead, so that its imports are seen too.
CHILD = """
import json, os, runpy, sys

def execv(path, argv):
    sys.argv = [argv[2], *argv[3:]]
    runpy.run_module(argv[2], run_name="__main__", alter_sys=True)

os.execv = execv
from hlvs.cli import main
try:
    main(json.loads(sys.argv[1]))
except SystemExit as exc:
    code = exc.code
else:
    code = 0
sys.stdout.write("\\nRESULT " + json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def _forwarded() -> list[list[str]]:
    return sorted(
        parser.prog.split()[1:]
        for parser in walk(build_parser())
        if parser.get_default("forwarded")
    )


def _run(argv: list[str]) -> tuple[str, dict[str, object]]:
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(argv)],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    text, _, result = done.stdout.rpartition("\nRESULT ")
    assert result, f"hlvs {' '.join(argv)}: no result; stderr: {done.stderr[-500:]}"
    return text, json.loads(result)


def _help(words: list[str]) -> tuple[str, dict[str, object]]:
    return _run([*words, "--help"])


def test_there_are_forwarded_commands() -> None:
    commands = _forwarded()
    assert ["render"] in commands and ["bench", "sim"] in commands and ["bench", "envs"] in commands


def test_forwarded_help_imports_nothing_heavy() -> None:
    commands = _forwarded()
    with ThreadPoolExecutor(max_workers=2) as pool:
        outcomes = list(pool.map(_help, commands))
    problems = []
    for words, (text, result) in zip(commands, outcomes, strict=True):
        name = " ".join(words)
        if result["code"] != 0 or f"usage: hlvs {name}" not in text:
            problems.append(f"hlvs {name} --help: exit {result['code']}, usage {text[:80]!r}")
        modules = result["modules"]
        assert isinstance(modules, list)
        heavy = sorted(
            m for m in modules if any(m == h or m.startswith(h + ".") for h in HEAVY_AFTER_PARSE)
        )
        if heavy:
            problems.append(f"hlvs {name} --help imported {heavy[:8]}")
    assert not problems, "\n".join(problems)


def test_the_check_sees_the_imports_of_an_executed_module() -> None:
    """The same child running a forwarded benchmark for real does import MuJoCo."""
    _, result = _run(["bench", "sim", "--robots", "0", "--sim-seconds", "1", "--json"])
    assert result["code"] == 0
    assert "mujoco" in result["modules"]  # type: ignore[operator]
