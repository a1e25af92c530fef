"""`cmake --install --prefix P` puts the package where P's Python finds it: --prefix ~/.local into
the user site, so that `python3 -c "import softsight"` works with no setting (it landed in
P/lib/python3.X/dist-packages, which no Python searches); any other P under P's own layout, with
the PYTHONPATH to set said at install time. It imports from there alone, with its version and
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
IMPORT = ("import softsight, importlib.metadata as m; print(softsight.__file__); "
          "print(softsight.__version__, m.version('softsight'), m.metadata('softsight')['License'])")
needs_ctest = pytest.mark.skipif(not (CMAKE and BUILD_DIR), reason="run by ctest (python.test_install)")


def clean_environment(**values: str) -> dict[str, str]:
    """This environment without what would point Python elsewhere, plus `values`."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONUSERBASE", "PYTHONNOUSERSITE")}
    return dict(env, **values)


def install_python_package(prefix: Path, env: dict[str, str]) -> str:
    """The package, and the libraries its extension links (shared ones, found from its own place)."""
    said = ""
    for component in ("python", "library"):
        said += subprocess.run([CMAKE, "--install", BUILD_DIR, "--component", component, "--prefix",
                                str(prefix)], env=env, check=True, capture_output=True, text=True,
                               timeout=60).stdout
    return said


def imported_from(env: dict[str, str], cwd: Path) -> Path:
    out = subprocess.run([sys.executable, "-c", IMPORT], env=env, cwd=cwd, check=True,
                         capture_output=True, text=True, timeout=60)
    where, versions = out.stdout.splitlines()
    version, meta_version, licence = versions.split()
    assert version == meta_version and licence == "Apache-2.0"
    return Path(where)


@needs_ctest
def test_install_into_the_user_base_is_found_by_python_as_it_is(tmp_path):
    home = tmp_path / "home"  # A HOME of its own: ~/.local is the user base.
    env = clean_environment(HOME=str(home))
    said = install_python_package(home / ".local", env)
    user_site = Path(subprocess.run([sys.executable, "-m", "site", "--user-site"], env=env,
                                    check=True, capture_output=True, text=True).stdout.strip())
    assert user_site.is_relative_to(home / ".local")
    assert (user_site / "softsight" / "__init__.py").exists()
    assert "where" in said and "finds it" in said and "PYTHONPATH" not in said
    assert imported_from(env, cwd=tmp_path) == user_site / "softsight" / "__init__.py"


@needs_ctest
def test_install_elsewhere_says_the_pythonpath_and_holds_the_whole_package(tmp_path):
    env = clean_environment(HOME=str(tmp_path / "home"))
    said = install_python_package(tmp_path / "prefix", env)
    sites = [p.parent.parent for p in (tmp_path / "prefix").rglob("softsight/__init__.py")]
    assert len(sites) == 1, sites
    site = sites[0]
    assert f"PYTHONPATH={site}" in said
    assert (site / "softsight" / "__init__.pyi").exists() and (site / "softsight" / "py.typed").exists()
    # Every file of the package the build tree assembles is installed (a new module added to
    # the package but not to python/CMakeLists.txt's list would be missing here).
    built = {p.name for p in (Path(BUILD_DIR) / "python" / "softsight").iterdir()
             if p.name != "__pycache__"}
    installed = {p.name for p in (site / "softsight").iterdir()}
    assert built - installed == set()
    assert imported_from(dict(env, PYTHONPATH=str(site)), cwd=tmp_path) == site / "softsight" / "__init__.py"
