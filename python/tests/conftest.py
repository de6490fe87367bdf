"""Shared fixtures: the repository's root, its scenes and the command line it builds."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


def cli_path() -> Path:
    """The ``bondmech`` command line: $BONDMECH_CLI, else the one ``cargo build``/``cargo test``
    left in target/ (debug first, the build the README's commands make)."""
    env = os.environ.get("BONDMECH_CLI")
    if env:
        return Path(env)
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "bondmech"
        if p.is_file():
            return p
    if shutil.which("bondmech"):
        return Path(shutil.which("bondmech"))  # type: ignore[arg-type]
    pytest.fail("no bondmech command line: run `cargo build` (or set BONDMECH_CLI)")


@pytest.fixture(scope="session")
def cli():
    path = cli_path()

    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(path), *args], cwd=ROOT, capture_output=True, text=True, check=check
        )

    return run


@pytest.fixture
def double_pendulum_path() -> Path:
    return SCENES / "double_pendulum.json"
