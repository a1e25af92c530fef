"""`cmake --install --prefix P` puts the package under P (P/lib/python3.X/dist-packages, or the
site-packages of a virtual environment at P): it imports from there alone, with its version and
licence metadata, and its extension finds the shared libraries installed with it. (`pip install .`
is checked by ctest's install.pip.)"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

CMAKE = os.environ.get("SOFTSIGHT_CMAKE")
BUILD_DIR = os.environ.get("SOFTSIGHT_BUILD_DIR")
INSTALL_DIR = os.environ.get("SOFTSIGHT_PYTHON_INSTALL_DIR")


@pytest.mark.skipif(not (CMAKE and BUILD_DIR and INSTALL_DIR), reason="run by ctest (python.test_install)")
def test_cmake_install_puts_an_importable_package_into_site_packages(tmp_path):
    # The package, and the libraries its extension links (shared ones, found from its own place).
    for component in ("python", "library"):
        subprocess.run([CMAKE, "--install", BUILD_DIR, "--component", component, "--prefix", str(tmp_path)],
                       check=True, capture_output=True, timeout=60)
    site = tmp_path / INSTALL_DIR  # A relative install dir is under the prefix.
    assert not Path(INSTALL_DIR).is_absolute(), "the default install dir follows --prefix"
    assert (site / "softsight" / "__init__.py").exists()
    assert (site / "softsight" / "__init__.pyi").exists() and (site / "softsight" / "py.typed").exists()
    # Every file of the package the build tree assembles is installed (a new module added to
    # the package but not to python/CMakeLists.txt's list would be missing here).
    built = {p.name for p in (Path(BUILD_DIR) / "python" / "softsight").iterdir()
             if p.name != "__pycache__"}
    installed = {p.name for p in (site / "softsight").iterdir()}
    assert built - installed == set()
    code = ("import softsight, importlib.metadata as m; print(softsight.__file__); "
            "print(softsight.__version__, m.version('softsight'), m.metadata('softsight')['License'])")
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = subprocess.run([sys.executable, "-c", code], env=dict(clean, PYTHONPATH=str(site)),
                         cwd=tmp_path, check=True, capture_output=True, text=True, timeout=60)
    where, versions = out.stdout.splitlines()
    assert where.startswith(str(site))
    version, meta_version, licence = versions.split()
    assert version == meta_version and licence == "Apache-2.0"
