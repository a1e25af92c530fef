"""The type stubs hold under `mypy --strict`: the stubs themselves and docs/python.md's examples
(every ```python block, in order, as one module: the page reads as one session) type-check
against them. Needs mypy (Debian: mypy, which scripts/setup.sh installs)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import softsight
from conftest import SOURCE_DIR

PACKAGE_PARENT = Path(softsight.__file__).resolve().parents[1]  # build/python, or site-packages


@pytest.fixture(scope="module")
def mypy_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One cache for both checks: the second reuses the standard library's analysis (~10 s)."""
    return tmp_path_factory.mktemp("mypy-cache")


def mypy(tmp_path: Path, cache: Path, *targets: str) -> subprocess.CompletedProcess:
    try:
        import mypy  # noqa: F401
    except ImportError:
        pytest.skip("mypy is not installed (Debian: apt install mypy; scripts/setup.sh does)")
    # Excused, for others' code only: cv2 (OpenCV 4.6) ships no type information, and the
    # examples may call distributed.Client, which is untyped. A softsight function without types
    # fails the stubs' own check (--strict: disallow_untyped_defs).
    config = tmp_path / "mypy.ini"
    # distributed (and the dask it imports) is not analysed: it is large (30 s of mypy's time)
    # and the examples' calls into it are untyped calls either way.
    config.write_text("[mypy]\n\n[mypy-cv2.*]\nignore_missing_imports = True\n\n"
                      "[mypy-distributed.*,dask.*]\nfollow_imports = skip\n\n"
                      "[mypy-python_md_examples]\ndisallow_untyped_calls = False\n")
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--config-file", str(config),
         "--cache-dir", str(cache), "--no-error-summary", *targets],
        env={"MYPYPATH": str(PACKAGE_PARENT), "PATH": "/usr/bin:/bin"},
        cwd=tmp_path, capture_output=True, text=True, timeout=180)


def test_the_stubs_are_clean_under_mypy_strict(tmp_path, mypy_cache):
    stubs = sorted(str(p) for p in (PACKAGE_PARENT / "softsight").glob("*.pyi"))
    assert {Path(p).name for p in stubs} >= {"__init__.pyi", "batch.pyi", "geometry.pyi",
                                             "sim.pyi", "calib.pyi"}
    result = mypy(tmp_path, mypy_cache, *stubs)
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_docs_examples_type_check_against_the_stubs(tmp_path, mypy_cache):
    page = (SOURCE_DIR / "docs" / "python.md").read_text()
    blocks = re.findall(r"^```python\n(.*?)^```", page, flags=re.S | re.M)
    assert len(blocks) >= 4  # The tour, progress, errors, Dask (a page without them is moved).
    example = tmp_path / "python_md_examples.py"
    example.write_text("\n".join(blocks))
    result = mypy(tmp_path, mypy_cache, str(example))
    assert result.returncode == 0, result.stdout + result.stderr
