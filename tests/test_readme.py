"""Every command line in the README runs as written (but the two set-up commands, which CI
itself runs): the shell block in a fresh folder holding the checkout's .venv and inputs, and
the Python block. A line ends with the exit code it expects when its comment says "(exit N)".
Units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, re.S)


def commands(block: str) -> list[tuple[str, int]]:
    """(command, expected exit code) per command line: continuations joined, comments cut;
    a comment on the following lines belongs to the command above it."""
    out: list[list] = []
    for line in block.replace("\\\n", " ").splitlines():
        code, _, comment = line.partition("  #")
        if line.lstrip().startswith("#"):
            code, comment = "", line
        if code.strip():
            out.append([code.strip(), 0])
        exit_code = re.search(r"\(exit (\d+)\)", comment)
        if exit_code and out:
            out[-1][1] = int(exit_code.group(1))
    return [(c, e) for c, e in out]


def test_the_readme_opens_with_the_two_set_up_commands():
    first = blocks("bash")[0]
    assert [c for c, _ in commands(first)] == ["make run", "make test"]
    assert README.index("```bash") < README.index("## ")


@pytest.mark.slow
def test_every_shell_command_of_the_readme_runs_as_written(tmp_path):
    """The block runs in one shell (``source`` applies to what follows); each line's exit
    code is checked; the files the lines promise exist afterwards."""
    (tmp_path / ".venv").symlink_to(Path(sys.prefix))
    (tmp_path / "inputs").symlink_to(ROOT / "inputs")
    script = ["set -u"]
    for command, expected in commands(blocks("bash")[1]):
        quoted = command.replace("'", "'\"'\"'")
        script.append(f"{command}\nrc=$?\nif [ $rc -ne {expected} ]; then "
                      f"echo 'README line failed (exit '$rc', expected {expected}): {quoted}' >&2; "
                      "exit 1; fi")
    env = {k: v for k, v in os.environ.items() if not k.startswith("DEMSTUDY_")}
    run = subprocess.run(["bash", "-c", "\n".join(script)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=1200)
    assert run.returncode == 0, run.stderr[-3000:]
    for name in ("deck/deck.in", "soft.h5", "hard.h5", "le3d.h5", "shear.h5", "hcs.h5",
                 "profiles.png", "fig-profiles.png", "fig-cooling.png", "fig-angles.png"):
        assert (tmp_path / name).exists(), name
    assert "Traceback" not in run.stderr


def test_the_python_block_of_the_readme_runs_as_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (python,) = blocks("python")
    namespace: dict = {}
    exec(compile(python, "README.md", "exec"), namespace)  # noqa: S102
    assert (tmp_path / "couette.png").stat().st_size > 20_000
    assert "statistics/vdf" in namespace["res"].groups
