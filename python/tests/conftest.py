"""Shared fixtures: the `softsight` program, the repository, and small rendered videos.

Run by ctest (python.test_*), which sets PYTHONPATH to the build tree's package and
SOFTSIGHT_BINARY / SOFTSIGHT_SOURCE_DIR; by hand:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests
"""

from __future__ import annotations

import csv
import os
import subprocess
from pathlib import Path
from typing import Dict, List

import pytest

import softsight

SOURCE_DIR = Path(os.environ.get("SOFTSIGHT_SOURCE_DIR", Path(__file__).resolve().parents[2]))
# The package sits in build/python/softsight; the program in build/src/app.
BINARY = Path(
    os.environ.get(
        "SOFTSIGHT_BINARY", Path(softsight.__file__).resolve().parents[2] / "src" / "app" / "softsight"
    )
)
MARKERS_YAML = SOURCE_DIR / "examples" / "markers.yaml"


def run_cli(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Runs the `softsight` program; returns the finished process (text output)."""
    assert BINARY.exists(), f"softsight program not found at {BINARY} (set SOFTSIGHT_BINARY)"
    result = subprocess.run([str(BINARY), *args], capture_output=True, text=True, timeout=120)
    if check and result.returncode != 0:
        raise AssertionError(f"softsight {' '.join(args)} failed: {result.stderr}")
    return result


def cli_error(*args: str) -> str:
    """The one-line message the program prints for bad input (after 'softsight CMD: error: ')."""
    result = run_cli(*args, check=False)
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = [line for line in result.stderr.splitlines() if ": error: " in line]
    assert len(lines) == 1, result.stderr
    return lines[0].split(": error: ", 1)[1]


def read_csv(path: Path) -> Dict[str, List[str]]:
    """A CSV file as columns of field texts."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: [row[i] for row in body] for i, name in enumerate(header)}


def render_video(path: Path, frames: int, seed: int = 1) -> Path:
    """A short lossless (HuffYUV) video of the bending scene, written by `softsight synth`."""
    run_cli("synth", "--scene", "bending", "--frames", str(frames), "--seed", str(seed),
            "--noise", "2", "--out", str(path), "-q")
    return path


@pytest.fixture(scope="session")
def bending_video(tmp_path_factory) -> Path:
    """24 frames of the bending scene (640x480, three colour markers)."""
    return render_video(tmp_path_factory.mktemp("video") / "bending.avi", frames=24)


@pytest.fixture(scope="session")
def markers_yaml() -> Path:
    return MARKERS_YAML
